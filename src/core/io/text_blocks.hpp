// Text read in blocks of whole lines, parsed on every core and taken in file order. A text
// cloud's parse (numbers from decimal text, about 100 ns a line) is all of its read, and a
// line-by-line reader ran it on one core: autzen_south as XYZ took 0.7 s for the bounds
// pre-pass and as long again for the read.
#pragma once

#include "io/file_stream.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>
#include <vector>

namespace omicron {

struct TextBlock {
    std::vector<char> bytes;     // whole lines; only the file's last may lack its '\n'
    std::uint64_t offset = 0;    // file offset of bytes[0]
    std::uint64_t firstLine = 1; // 1-based number of its first line
    std::uint64_t lines = 0;     // line breaks in it (its last line may have none)

    std::uint64_t endOffset() const { return offset + bytes.size(); }
};

// Cuts a file, from a line's start to its end, into blocks of whole lines, reading it in
// order on the calling thread.
class TextBlockReader {
public:
    static constexpr std::size_t kBlockBytes = std::size_t{256} << 10;

    // `firstLine` is the 1-based number of the line that starts at `offset`.
    TextBlockReader(const FileStream& stream, std::uint64_t offset, std::uint64_t firstLine);

    // The next block: about kBlockBytes of whole lines, more when one line is longer. False
    // at the end of the file. A line longer than LineReader::kMaxLineBytes throws
    // MalformedValue (a binary file read as text must not eat all memory).
    bool next(TextBlock& block);

private:
    const FileStream& m_stream;
    std::vector<char> m_carry; // the partial line after the last block's last line break
    std::uint64_t m_offset;    // file offset of the first byte not yet read
    std::uint64_t m_line;      // number of the line the next block starts with
};

// The lines of a block as LineReader returns them: without the terminator ("\n", "\r\n").
class TextBlockLines {
public:
    explicit TextBlockLines(const TextBlock& block) : m_block(block), m_nextLine(block.firstLine) {}

    bool next(std::string_view& line);
    std::uint64_t lineNumber() const { return m_lineNumber; } // of the last line returned
    std::uint64_t lineOffset() const { return m_block.offset + m_lineStart; } // its offset

private:
    const TextBlock& m_block;
    std::size_t m_at = 0;
    std::size_t m_lineStart = 0;
    std::uint64_t m_lineNumber = 0;
    std::uint64_t m_nextLine;
};

// Reads `stream` from `offset` (the start of line `firstLine`) to its end in TextBlocks and
// calls `parse(const TextBlock&, Parsed&)` for each on oneTBB's threads, a group of blocks at
// a time (the next group is read meanwhile), then `merge(const TextBlock&, Parsed&)` for each
// on the calling thread, in file order; merge returns false to stop. A `Parsed` is reused from
// group to group. An exception from parse is rethrown when its block's turn to merge comes:
// the first error in the file wins, as with a reader that reads line by line.
template <typename Parsed, typename Parse, typename Merge>
void parseTextBlocksInParallel(const FileStream& stream, std::uint64_t offset,
                               std::uint64_t firstLine, Parse&& parse, Merge&& merge) {
    // Blocks of a group are parsed in parallel; the group's last ones leave cores idle until
    // they are done, so a group holds several blocks a core. The first group holds one a
    // core: the first merge (a pre-pass's first preview points) comes that much sooner.
    const auto cores =
        static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    const std::size_t groupBlocks = 8 * cores;
    struct Group {
        std::vector<TextBlock> blocks;
        std::size_t wanted = 0;
        std::size_t count = 0;
        std::exception_ptr readError; // after the blocks read before it
    };
    TextBlockReader reader(stream, offset, firstLine);
    const auto read = [&reader](Group& group, std::size_t wanted) {
        group.wanted = wanted;
        group.count = 0;
        group.readError = nullptr;
        group.blocks.resize(std::max(group.blocks.size(), wanted));
        try {
            while (group.count < wanted && reader.next(group.blocks[group.count])) {
                ++group.count;
            }
        } catch (...) {
            group.readError = std::current_exception();
        }
    };
    Group groups[2];
    std::vector<Parsed> parsed(groupBlocks);
    std::vector<std::exception_ptr> errors(groupBlocks);
    read(groups[0], cores);
    for (int current = 0;; current = 1 - current) {
        Group& group = groups[current];
        Group& following = groups[1 - current];
        const bool more = group.count == group.wanted && !group.readError;
        tbb::task_group reading;
        if (more) {
            reading.run([&] { read(following, groupBlocks); });
        }
        tbb::parallel_for(std::size_t{0}, group.count, [&](std::size_t i) {
            errors[i] = nullptr;
            try {
                parse(static_cast<const TextBlock&>(group.blocks[i]), parsed[i]);
            } catch (...) {
                errors[i] = std::current_exception();
            }
        });
        reading.wait();
        for (std::size_t i = 0; i < group.count; ++i) {
            if (errors[i]) {
                std::rethrow_exception(errors[i]);
            }
            if (!merge(static_cast<const TextBlock&>(group.blocks[i]), parsed[i])) {
                return;
            }
        }
        if (group.readError) {
            std::rethrow_exception(group.readError);
        }
        if (!more) {
            return;
        }
    }
}

} // namespace omicron
