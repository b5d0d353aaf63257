// Text in blocks of whole lines: the blocks are the file from the given line on, cut at line
// breaks, numbered as LineReader numbers the lines; parsed in parallel, they are merged in file
// order, the first error in the file wins whichever block fails first, and a merge can stop.
#include "io/input_error.hpp"
#include "io/line_reader.hpp"
#include "io/text_blocks.hpp"
#include "test_files.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <gtest/gtest.h>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace omicron {
namespace {

using test::TempDir;
using test::writeText;

// Lines of many lengths (empty ones, CRLF ones and, every 5,000 lines, one longer than a
// block), over several blocks, the last without a line break.
std::string variedText() {
    std::string text;
    for (int i = 0; i < 40'000; ++i) {
        if (i % 97 == 0) {
            text += "\n";
        } else if (i % 5'000 == 4'999) {
            text += std::string(TextBlockReader::kBlockBytes + 1000, 'x') + "\n";
        } else {
            text += std::to_string(i) + std::string(static_cast<std::size_t>(i % 23), ' ') +
                    (i % 3 == 0 ? "\r\n" : "\n");
        }
    }
    return text + "the last line";
}

struct Line {
    std::string text;
    std::uint64_t number;
    std::uint64_t offset;
    bool operator==(const Line&) const = default;
};

TEST(TextBlocks, BlocksAreTheFileCutAtLineBreaksAndReadAsLineReaderReadsIt) {
    TempDir dir;
    const std::string path = dir.file("text.txt");
    const std::string text = variedText();
    writeText(path, text);
    // Start at a line in the middle, as the XYZ reader starts at its first data line.
    const std::uint64_t start = text.find('\n', 1000) + 1;
    const std::uint64_t startLine =
        1 + static_cast<std::uint64_t>(std::count(text.begin(), text.begin() + start, '\n'));

    FileStream stream(path);
    stream.seek(start);
    LineReader reference(stream, startLine);
    std::vector<Line> expected;
    std::string_view line;
    while (reference.next(line)) {
        expected.push_back({std::string(line), reference.lineNumber(), reference.lineOffset()});
    }

    TextBlockReader reader(stream, start, startLine);
    TextBlock block;
    std::string joined;
    std::vector<Line> lines;
    std::uint64_t nextLine = startLine;
    int blocks = 0;
    while (reader.next(block)) {
        ++blocks;
        EXPECT_EQ(block.offset, start + joined.size());
        EXPECT_EQ(block.firstLine, nextLine);
        const std::string bytes(block.bytes.begin(), block.bytes.end());
        EXPECT_EQ(block.lines,
                  static_cast<std::uint64_t>(std::count(bytes.begin(), bytes.end(), '\n')));
        if (block.endOffset() != text.size()) {
            EXPECT_EQ(bytes.back(), '\n') << "block " << blocks << " cuts a line";
        }
        joined += bytes;
        nextLine += block.lines;
        TextBlockLines blockLines(block);
        while (blockLines.next(line)) {
            lines.push_back({std::string(line), blockLines.lineNumber(), blockLines.lineOffset()});
        }
    }
    EXPECT_GT(blocks, 8);
    EXPECT_EQ(joined, text.substr(start));
    EXPECT_EQ(lines, expected);
}

TEST(TextBlocks, ALineOverTheLimitIsMalformedNamingItsNumber) {
    TempDir dir;
    const std::string path = dir.file("binary.txt");
    writeText(path, "1 2 3\n4 5 6\n" + std::string(LineReader::kMaxLineBytes + 10, 'b') + "\n");
    FileStream stream(path);
    TextBlockReader reader(stream, 0, 1);
    TextBlock block;
    try {
        while (reader.next(block)) {
        }
        FAIL() << "expected MalformedValue";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::MalformedValue) << error.what();
        EXPECT_EQ(error.location().value, 3u) << error.what();
        EXPECT_NE(std::string(error.what()).find("without a line break"), std::string::npos);
    }
}

// A file of `lines` lines "0\n", "1\n", ...
std::string numberedLines(int lines) {
    std::string text;
    for (int i = 0; i < lines; ++i) {
        text += std::to_string(i) + "\n";
    }
    return text;
}

struct Sum {
    std::uint64_t lines = 0;
    std::uint64_t total = 0;
};

void sumBlock(const TextBlock& block, Sum& sum) {
    sum = {};
    TextBlockLines lines(block);
    std::string_view line;
    while (lines.next(line)) {
        ++sum.lines;
        sum.total += std::stoull(std::string(line));
    }
}

TEST(TextBlocksInParallel, EveryBlockIsParsedOnceAndMergedInFileOrder) {
    TempDir dir;
    const std::string path = dir.file("numbers.txt");
    constexpr int kLines = 400'000; // about 2.6 MB: several groups of blocks
    writeText(path, numberedLines(kLines));
    FileStream stream(path);
    std::uint64_t nextOffset = 0, nextLine = 1, lines = 0, total = 0;
    std::thread::id merger;
    parseTextBlocksInParallel<Sum>(stream, 0, 1, sumBlock, [&](const TextBlock& block, Sum& sum) {
        EXPECT_EQ(block.offset, nextOffset);
        EXPECT_EQ(block.firstLine, nextLine);
        EXPECT_EQ(sum.lines, block.lines);
        nextOffset = block.endOffset();
        nextLine += block.lines;
        lines += sum.lines;
        total += sum.total;
        merger = std::this_thread::get_id();
        return true;
    });
    EXPECT_EQ(nextOffset, stream.size());
    EXPECT_EQ(lines, static_cast<std::uint64_t>(kLines));
    EXPECT_EQ(total, std::uint64_t{kLines} * (kLines - 1) / 2);
    EXPECT_EQ(merger, std::this_thread::get_id()) << "merged off the calling thread";
}

TEST(TextBlocksInParallel, TheFirstErrorInTheFileWinsWhicheverBlockFailsFirst) {
    TempDir dir;
    const std::string path = dir.file("numbers.txt");
    writeText(path, numberedLines(300'000));
    FileStream stream(path);
    // Two bad lines in different blocks of the first group; the earlier one's block fails
    // last.
    constexpr std::uint64_t kEarly = 100'000, kLate = 250'000;
    std::uint64_t merged = 0;
    try {
        parseTextBlocksInParallel<Sum>(
            stream, 0, 1,
            [&](const TextBlock& block, Sum& sum) {
                sumBlock(block, sum);
                for (const std::uint64_t bad : {kEarly, kLate}) {
                    if (bad >= block.firstLine && bad < block.firstLine + block.lines) {
                        if (bad == kEarly) {
                            std::this_thread::sleep_for(std::chrono::milliseconds(100));
                        }
                        throw std::runtime_error("line " + std::to_string(bad));
                    }
                }
            },
            [&](const TextBlock& block, Sum&) {
                EXPECT_LE(block.firstLine + block.lines, kEarly) << "merged past the error";
                ++merged;
                return true;
            });
        FAIL() << "expected the parse's error";
    } catch (const std::runtime_error& error) {
        EXPECT_EQ(std::string(error.what()), "line " + std::to_string(kEarly));
    }
    EXPECT_GT(merged, 0u);
}

TEST(TextBlocksInParallel, AMergeThatReturnsFalseStopsTheRead) {
    TempDir dir;
    const std::string path = dir.file("numbers.txt");
    writeText(path, numberedLines(400'000));
    FileStream stream(path);
    int merges = 0;
    parseTextBlocksInParallel<Sum>(stream, 0, 1, sumBlock,
                                   [&](const TextBlock&, Sum&) { return ++merges < 3; });
    EXPECT_EQ(merges, 3);
}

} // namespace
} // namespace omicron
