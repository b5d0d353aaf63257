// Cutting sorted codes into leaves, and how much of a growing prefix may be cut now.
#include "build/leaf_runs.hpp"

#include <algorithm>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>
#include <random>
#include <string>
#include <vector>

namespace omicron {
namespace {

// The centres of the level-21 cells of `codes`: points whose codes are exactly `codes`.
std::vector<glm::vec3> toPositions(const std::vector<morton::Code>& codes) {
    std::vector<glm::vec3> positions;
    for (const morton::Code code : codes) {
        const morton::Cell cell = morton::decode(code);
        const auto centre = [](std::uint32_t c) {
            return (static_cast<float>(c) + 0.5f) / static_cast<float>(morton::kCellsPerAxis);
        };
        positions.emplace_back(centre(cell.x), centre(cell.y), centre(cell.z));
        EXPECT_EQ(morton::encodeUnit(positions.back().x, positions.back().y, positions.back().z),
                  code);
    }
    return positions;
}

// Level-21 codes whose level-`level` prefixes are the given cells' codes, sorted.
std::vector<morton::Code> codesWithRuns(const std::vector<std::size_t>& runLengths, int level) {
    std::vector<morton::Code> codes;
    morton::Code cell = morton::encode({0, 0, 0}, level);
    const int shift = 3 * (morton::kMaxLevel - level);
    for (std::size_t length : runLengths) {
        for (std::size_t i = 0; i < length; ++i) {
            codes.push_back((cell << shift) | (i % (morton::Code{1} << shift)));
        }
        std::sort(codes.end() - static_cast<std::ptrdiff_t>(length), codes.end());
        cell += 3; // skips cells: runs are not always siblings
    }
    return codes;
}

TEST(LeafRuns, EndOfRunMatchesALinearScanForEveryRunLength) {
    std::vector<std::size_t> lengths;
    for (std::size_t length = 1; length <= 70; ++length) {
        lengths.push_back(length);
    }
    lengths.push_back(1000);
    lengths.push_back(1);
    const int level = 5;
    const auto positions = toPositions(codesWithRuns(lengths, level));
    std::size_t begin = 0;
    for (std::size_t length : lengths) {
        EXPECT_EQ(endOfRun(positions, begin, positions.size(), level), begin + length);
        // A range that ends inside the run stops there.
        EXPECT_EQ(endOfRun(positions, begin, begin + (length + 1) / 2, level),
                  begin + (length + 1) / 2);
        // The mirror search finds the run's start from its last point.
        EXPECT_EQ(startOfRun(positions, begin + length - 1, level), begin);
        begin += length;
    }
}

// Runs found by comparing every code with the one before it.
std::vector<LeafRun> referenceRuns(const std::vector<morton::Code>& codes, std::size_t begin,
                                   std::size_t end, int level) {
    std::vector<LeafRun> runs;
    const int shift = 3 * (morton::kMaxLevel - level);
    for (std::size_t i = begin; i < end; ++i) {
        if (i == begin || (codes[i] >> shift) != (codes[i - 1] >> shift)) {
            runs.push_back({codes[i] >> shift, static_cast<std::uint32_t>(i), 0});
        }
        ++runs.back().count;
    }
    return runs;
}

// The block codes of `codes` (block_codes.hpp): every 64th code.
std::vector<morton::Code> blockCodesOf(const std::vector<morton::Code>& codes) {
    std::vector<morton::Code> index;
    for (std::size_t i = 0; i < codes.size(); i += kBlockCodePoints) {
        index.push_back(codes[i]);
    }
    return index;
}

// The indexes a scan of [0, end) may get: none, exactly the entries of [0, end) (what the
// builder passes while input grows), and the whole cloud's.
std::vector<std::pair<std::string, BlockCodes>> indexesFor(const std::vector<morton::Code>& index,
                                                           std::size_t end) {
    return {{"no index", {}},
            {"index of [0, end)", BlockCodes(index).first(blockCodeCount(end))},
            {"whole index", BlockCodes(index)}};
}

void expectSameRuns(const std::vector<LeafRun>& found, const std::vector<LeafRun>& expected) {
    ASSERT_EQ(found.size(), expected.size());
    for (std::size_t r = 0; r < found.size(); ++r) {
        ASSERT_EQ(found[r].code, expected[r].code) << "run " << r;
        ASSERT_EQ(found[r].begin, expected[r].begin) << "run " << r;
        ASSERT_EQ(found[r].count, expected[r].count) << "run " << r;
    }
}

TEST(LeafRuns, FindLeafRunsMatchesAPlainScanAcrossParallelBlocks) {
    // Every run length from 1 to 70 (around the scan's 16-code skips), runs longer than a
    // parallel block, and sub-ranges that start and end inside runs.
    std::vector<std::size_t> lengths;
    for (std::size_t length = 1; length <= 70; ++length) {
        lengths.push_back(length);
    }
    lengths.push_back(40000);
    for (std::size_t length = 70; length >= 1; --length) {
        lengths.push_back(length);
    }
    lengths.push_back(100000);
    lengths.push_back(3);
    const int level = 6;
    const auto codes = codesWithRuns(lengths, level);
    const auto positions = toPositions(codes);
    const auto index = blockCodesOf(codes);
    for (const auto& [begin, end] : std::vector<std::pair<std::size_t, std::size_t>>{
             {0, codes.size()}, {1, codes.size() - 1}, {2500, 2600}, {2600, codes.size() - 5}}) {
        for (const auto& [name, blockCodes] : indexesFor(index, end)) {
            std::vector<LeafRun> runs;
            findLeafRuns(positions, blockCodes, begin, end, level, runs);
            SCOPED_TRACE("range " + std::to_string(begin) + ".." + std::to_string(end) + ", " +
                         name);
            expectSameRuns(runs, referenceRuns(codes, begin, end, level));
        }
    }
}

TEST(LeafRuns, FindLeafRunsOnRandomCodesAtEveryDepth) {
    std::mt19937_64 random(17);
    std::vector<morton::Code> codes(200000);
    for (morton::Code& code : codes) {
        code = (morton::Code{1} << 63) | (random() >> 1 >> 4 * (random() % 4));
    }
    codes.back() = ~morton::Code{0}; // the far corner: every coordinate bit set
    std::sort(codes.begin(), codes.end());
    const auto positions = toPositions(codes);
    const auto index = blockCodesOf(codes);
    for (const int level : {1, 4, 7, 12, 21}) {
        for (const std::size_t begin : {std::size_t{0}, std::size_t{1000}}) {
            const std::size_t end = codes.size() - begin;
            for (const auto& [name, blockCodes] : indexesFor(index, end)) {
                std::vector<LeafRun> runs;
                findLeafRuns(positions, blockCodes, begin, end, level, runs);
                SCOPED_TRACE("level " + std::to_string(level) + ", from " +
                             std::to_string(begin) + ", " + name);
                expectSameRuns(runs, referenceRuns(codes, begin, end, level));
            }
        }
    }
}

TEST(LeafRuns, FindLeafRunsCoversTheRangeWithOneRunPerCell) {
    const std::vector<std::size_t> lengths = {3, 1, 1, 17, 256, 2};
    const int level = 4;
    const auto codes = codesWithRuns(lengths, level);
    std::vector<LeafRun> runs;
    findLeafRuns(toPositions(codes), blockCodesOf(codes), 0, codes.size(), level, runs);
    ASSERT_EQ(runs.size(), lengths.size());
    std::uint32_t begin = 0;
    for (std::size_t r = 0; r < runs.size(); ++r) {
        EXPECT_EQ(runs[r].begin, begin);
        EXPECT_EQ(runs[r].count, lengths[r]);
        EXPECT_EQ(runs[r].code, morton::codeAtLevel(codes[begin], level));
        begin += runs[r].count;
    }
}

TEST(LeafRuns, InsertableEndHoldsBackTheRunThatMayContinue) {
    const int level = 3;
    const auto positions = toPositions(codesWithRuns({4, 5, 6}, level));
    // Input so far ends inside the third run: it is held back.
    EXPECT_EQ(insertableEnd(positions, 0, 12, false, level, 1000), 9u);
    // Input ended: everything goes.
    EXPECT_EQ(insertableEnd(positions, 0, 12, true, level, 1000), 12u);
    // The per-pass limit cuts before the run it lands in.
    EXPECT_EQ(insertableEnd(positions, 0, 15, false, level, 6), 4u);
    // A single run longer than the limit is taken whole once its end is known...
    EXPECT_EQ(insertableEnd(positions, 4, 15, false, level, 2), 9u);
    // ...and waited for while it may still grow.
    EXPECT_EQ(insertableEnd(positions, 9, 15, false, level, 2), 9u);
    EXPECT_EQ(insertableEnd(positions, 9, 15, true, level, 2), 15u);
    EXPECT_EQ(insertableEnd(positions, 15, 15, true, level, 2), 15u);
}

TEST(LeafRuns, InsertableEndWithASiblingGroupShiftKeepsSiblingsTogether) {
    const int level = 3;
    const int groupLevel = level - 1;
    // Two sibling leaves (cells 0 and 1 of one parent), then a leaf of another parent.
    std::vector<morton::Code> codes;
    const int leafShift = 3 * (morton::kMaxLevel - level);
    for (morton::Code cell :
         {morton::Code{0b1000000000}, morton::Code{0b1000000001}, morton::Code{0b1000001000}}) {
        codes.push_back(cell << leafShift);
        codes.push_back((cell << leafShift) | 5);
    }
    const auto positions = toPositions(codes);
    EXPECT_EQ(insertableEnd(positions, 0, 3, false, groupLevel, 100), 0u);
    EXPECT_EQ(insertableEnd(positions, 0, 5, false, groupLevel, 100), 4u);
    EXPECT_EQ(insertableEnd(positions, 0, 6, true, groupLevel, 100), 6u);
}

} // namespace
} // namespace omicron
