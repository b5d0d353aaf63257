// Morton module against a brute-force bit-by-bit reference, on random and adversarial input.
#include "points/morton.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace omicron::morton {
namespace {

// Reference: interleave bit by bit, x lowest of each triple, sentinel above.
Code referenceEncode(Cell cell, int lvl) {
    Code code = 1;
    for (int bit = lvl - 1; bit >= 0; --bit) {
        code = code << 3 | ((cell.z >> bit) & 1u) << 2 | ((cell.y >> bit) & 1u) << 1 |
               ((cell.x >> bit) & 1u);
    }
    return code;
}

int referenceLevel(Code code) {
    int bits = 0;
    while (code > 1) {
        code >>= 1;
        ++bits;
    }
    return bits / 3;
}

std::vector<std::pair<Cell, int>> adversarialCells() {
    std::vector<std::pair<Cell, int>> cells;
    for (int lvl = 0; lvl <= kMaxLevel; ++lvl) {
        const std::uint32_t top = lvl == 0 ? 0u : (1u << lvl) - 1u;
        const std::uint32_t half = lvl == 0 ? 0u : 1u << (lvl - 1);
        for (std::uint32_t x : {0u, top, half, half == 0 ? 0u : half - 1u}) {
            for (std::uint32_t y : {0u, top, half}) {
                for (std::uint32_t z : {0u, top, half == 0 ? 0u : half - 1u}) {
                    cells.push_back({{x, y, z}, lvl});
                }
            }
        }
    }
    return cells;
}

std::vector<std::pair<Cell, int>> randomCells(std::size_t count, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    std::vector<std::pair<Cell, int>> cells;
    for (std::size_t i = 0; i < count; ++i) {
        const int lvl = static_cast<int>(random() % (kMaxLevel + 1));
        const std::uint64_t mask = (std::uint64_t{1} << lvl) - 1;
        cells.push_back({{static_cast<std::uint32_t>(random() & mask),
                          static_cast<std::uint32_t>(random() & mask),
                          static_cast<std::uint32_t>(random() & mask)},
                         lvl});
    }
    return cells;
}

class MortonProperty : public ::testing::TestWithParam<const char*> {
protected:
    std::vector<std::pair<Cell, int>> cells() const {
        return std::string(GetParam()) == "adversarial" ? adversarialCells()
                                                        : randomCells(200000, 42);
    }
};

TEST_P(MortonProperty, EncodeMatchesReferenceAndDecodes) {
    for (const auto& [cell, lvl] : cells()) {
        const Code code = encode(cell, lvl);
        ASSERT_EQ(code, referenceEncode(cell, lvl)) << cell.x << "," << cell.y << "," << cell.z;
        ASSERT_TRUE(isValid(code));
        ASSERT_EQ(level(code), lvl);
        ASSERT_EQ(level(code), referenceLevel(code));
        ASSERT_EQ(decode(code), cell);
    }
}

TEST_P(MortonProperty, ParentChildAndAncestry) {
    for (const auto& [cell, lvl] : cells()) {
        const Code code = encode(cell, lvl);
        if (lvl > 0) {
            const Code up = parent(code);
            ASSERT_EQ(up, referenceEncode({cell.x >> 1, cell.y >> 1, cell.z >> 1}, lvl - 1));
            ASSERT_EQ(child(up, childIndex(code)), code);
            ASSERT_EQ(childIndex(code), (cell.x & 1u) | (cell.y & 1u) << 1 | (cell.z & 1u) << 2);
            ASSERT_TRUE(isAncestorOrSelf(up, code));
            ASSERT_FALSE(isAncestorOrSelf(code, up));
            ASSERT_TRUE(isAncestorOrSelf(kRoot, code));
        }
        for (int shallower = 0; shallower <= lvl; ++shallower) {
            const int shift = lvl - shallower;
            ASSERT_EQ(codeAtLevel(code, shallower),
                      referenceEncode({cell.x >> shift, cell.y >> shift, cell.z >> shift},
                                      shallower));
        }
        ASSERT_TRUE(isAncestorOrSelf(code, code));
    }
}

TEST_P(MortonProperty, SpanIsTheRightmostDescendantAndBoundsDescendants) {
    for (const auto& [cell, lvl] : cells()) {
        const Code code = encode(cell, lvl);
        const int maxLevel = kMaxLevel;
        const Code codeSpan = span(code, maxLevel);
        const int k = maxLevel - lvl;
        // Right-most descendant: every cell coordinate extended with all ones.
        const std::uint32_t ones = k == 0 ? 0u : (1u << k) - 1u;
        ASSERT_EQ(codeSpan, referenceEncode({cell.x << k | ones, cell.y << k | ones,
                                             cell.z << k | ones},
                                            maxLevel));
        ASSERT_EQ(level(codeSpan), maxLevel);
        ASSERT_TRUE(isAncestorOrSelf(code, codeSpan));
        // Placeholders repeated down to maxLevel reach the span.
        Code slot = code;
        while (level(slot) < maxLevel) {
            slot = placeholder(slot);
        }
        ASSERT_EQ(slot, codeSpan);
        if (lvl < maxLevel) {
            for (unsigned c = 0; c < 8; ++c) {
                ASSERT_LE(span(child(code, c), maxLevel), codeSpan);
            }
            ASSERT_EQ(span(child(code, 7), maxLevel), codeSpan);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Inputs, MortonProperty, ::testing::Values("random", "adversarial"));

TEST(Morton, RootAndFirstLevel) {
    EXPECT_EQ(encode({0, 0, 0}, 0), kRoot);
    EXPECT_EQ(level(kRoot), 0);
    EXPECT_EQ(encode({0, 0, 0}, 1), 0b1000u);
    EXPECT_EQ(encode({1, 1, 1}, 1), 0b1111u);
    EXPECT_EQ(encode({1, 0, 0}, 1), 0b1001u);
    EXPECT_EQ(encode({0, 1, 0}, 1), 0b1010u);
    EXPECT_EQ(encode({0, 0, 1}, 1), 0b1100u);
    EXPECT_EQ(placeholder(kRoot), 0b1111u);
    EXPECT_EQ(span(kRoot, 1), 0b1111u);
    EXPECT_EQ(span(kRoot, 0), kRoot);
}

TEST(Morton, DeepestLevelUsesAll64Bits) {
    const std::uint32_t top = kCellsPerAxis - 1;
    EXPECT_EQ(encode({top, top, top}, kMaxLevel), std::numeric_limits<Code>::max());
    EXPECT_EQ(encode({0, 0, 0}, kMaxLevel), Code{1} << 63);
    EXPECT_EQ(level(std::numeric_limits<Code>::max()), kMaxLevel);
    EXPECT_EQ(span(kRoot, kMaxLevel), std::numeric_limits<Code>::max());
}

TEST(Morton, InvalidCodesAreDetected) {
    EXPECT_FALSE(isValid(0));
    EXPECT_FALSE(isValid(0b10));
    EXPECT_FALSE(isValid(0b100));
    EXPECT_TRUE(isValid(0b1000));
}

TEST(MortonQuantize, MaxFaceLandsInLastCellNeverWraps) {
    EXPECT_EQ(quantize(1.0f), kCellsPerAxis - 1);
    EXPECT_EQ(quantize(std::nextafter(1.0f, 0.0f)), kCellsPerAxis - 1);
    EXPECT_EQ(quantize(1.5f), kCellsPerAxis - 1);
    EXPECT_EQ(quantize(std::numeric_limits<float>::infinity()), kCellsPerAxis - 1);
    EXPECT_EQ(encodeUnit(1.0f, 1.0f, 1.0f), std::numeric_limits<Code>::max());
}

TEST(MortonQuantize, MinFaceAndOutOfRangeClampToZero) {
    EXPECT_EQ(quantize(0.0f), 0u);
    EXPECT_EQ(quantize(-0.0f), 0u);
    EXPECT_EQ(quantize(-1e-7f), 0u);
    EXPECT_EQ(quantize(std::numeric_limits<float>::quiet_NaN()), 0u);
    EXPECT_EQ(quantize(-std::numeric_limits<float>::infinity()), 0u);
}

TEST(MortonQuantize, CellBoundariesAreExact) {
    // k / 2^21 is exactly representable in float: it must open cell k.
    for (std::uint32_t k : {1u, 2u, 3u, 1000u, 1u << 20, (1u << 21) - 2u, (1u << 21) - 1u}) {
        const float boundary = static_cast<float>(k) / static_cast<float>(kCellsPerAxis);
        EXPECT_EQ(quantize(boundary), k);
        EXPECT_EQ(quantize(std::nextafter(boundary, 0.0f)), k - 1);
    }
}

TEST(MortonQuantize, MonotoneInEachAxis) {
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int i = 0; i < 100000; ++i) {
        const float a = unit(random);
        const float b = unit(random);
        if (a <= b) {
            ASSERT_LE(quantize(a), quantize(b)) << a << " " << b;
        }
    }
}

TEST(MortonOrder, ShallowerDepthIsAPrefixOfTheDeepOrder) {
    std::mt19937_64 random(11);
    std::vector<Code> codes;
    for (int i = 0; i < 50000; ++i) {
        const std::uint32_t mask = kCellsPerAxis - 1;
        codes.push_back(encode({static_cast<std::uint32_t>(random()) & mask,
                                static_cast<std::uint32_t>(random()) & mask,
                                static_cast<std::uint32_t>(random()) & mask},
                               kMaxLevel));
    }
    std::sort(codes.begin(), codes.end());
    for (int lvl : {1, 3, 7, 12, 20}) {
        for (std::size_t i = 1; i < codes.size(); ++i) {
            ASSERT_LE(codeAtLevel(codes[i - 1], lvl), codeAtLevel(codes[i], lvl));
        }
    }
}

} // namespace
} // namespace omicron::morton
