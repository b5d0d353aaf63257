// The parents' samples: size, distinctness, order and spread.
#include "build/parent_sampler.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <gtest/gtest.h>
#include <vector>

namespace omicron {
namespace {

TEST(ParentSampler, SampleSizeIsTheRoundedRatioAndAtLeastOne) {
    EXPECT_EQ(sampleSize(10, 0.2), 2u);
    EXPECT_EQ(sampleSize(12, 0.2), 2u); // 2.4
    EXPECT_EQ(sampleSize(13, 0.2), 3u); // 2.6
    EXPECT_EQ(sampleSize(2, 0.2), 1u);  // 0.4, but a parent keeps one point
    EXPECT_EQ(sampleSize(1, 0.2), 1u);
    EXPECT_EQ(sampleSize(7, 1.0), 7u);
    EXPECT_EQ(sampleSize(4000000000ull, 0.25), 1000000000u);
}

TEST(ParentSampler, RangeSampleIsEvenlySpacedAndDistinct) {
    std::vector<std::uint32_t> out(4);
    sampleRange(100, 8, out);
    EXPECT_EQ(out, (std::vector<std::uint32_t>{101, 103, 105, 107}));
    out.assign(1, 0);
    sampleRange(0, 9, out);
    EXPECT_EQ(out.front(), 4u) << "a single pick is the middle point";
    out.assign(9, 0);
    sampleRange(50, 9, out);
    EXPECT_EQ(out, (std::vector<std::uint32_t>{50, 51, 52, 53, 54, 55, 56, 57, 58}));
}

TEST(ParentSampler, RangePicksEqualTheStratifiedFormula) {
    // Pick j of count from n is floor((2j + 1) n / (2 count)), computed without a division per
    // pick: check against the formula in 128-bit arithmetic, also where (2j + 1) n overflows.
    __extension__ using Wide = unsigned __int128;
    std::vector<std::uint32_t> out;
    for (const std::uint64_t n : {1ull, 2ull, 7ull, 100ull, 4099ull, 123457ull, 4000000000ull}) {
        for (const std::uint64_t count : {1ull, 2ull, 3ull, 17ull, 1000ull}) {
            if (count > n) {
                continue;
            }
            out.assign(count, 0);
            sampleRange(0, static_cast<std::uint32_t>(n), out);
            for (std::uint64_t j = 0; j < count; ++j) {
                const auto expected =
                    static_cast<std::uint64_t>(Wide{2 * j + 1} * n / (Wide{2} * count));
                ASSERT_EQ(out[j], expected) << "n " << n << " count " << count << " j " << j;
            }
        }
    }
}

TEST(ParentSampler, ChildrenSampleDrawsFromEveryChildInProportion) {
    // Child 0 holds a range, child 1 a sample list, child 2 a range.
    const std::vector<std::uint32_t> childSample = {1000, 1003, 1010, 1011, 1020,
                                                    1021, 1030, 1031, 1040, 1041};
    std::array<OctreeNode, 3> nodes{};
    nodes[0].coveredBegin = 0;
    nodes[0].pointCount = nodes[0].coveredCount = 20;
    nodes[1].sampleIndices = childSample.data();
    nodes[1].coveredBegin = 1000;
    nodes[1].coveredCount = 50;
    nodes[1].pointCount = static_cast<std::uint32_t>(childSample.size());
    nodes[2].coveredBegin = 5000;
    nodes[2].pointCount = nodes[2].coveredCount = 10;
    const std::array<const OctreeNode*, 3> children = {&nodes[0], &nodes[1], &nodes[2]};
    std::vector<std::uint32_t> out(sampleSize(40, 0.25));
    ASSERT_EQ(out.size(), 10u);
    sampleChildren(children, out);
    EXPECT_TRUE(std::is_sorted(out.begin(), out.end()));
    EXPECT_EQ(std::adjacent_find(out.begin(), out.end()), out.end()) << "no duplicates";
    const auto from = [&](std::uint32_t lo, std::uint32_t hi) {
        return std::count_if(out.begin(), out.end(),
                             [&](std::uint32_t i) { return i >= lo && i < hi; });
    };
    EXPECT_EQ(from(0, 20), 5);
    EXPECT_EQ(from(1000, 1100), 2);
    EXPECT_EQ(from(5000, 5010), 3);
    for (std::uint32_t index : out) {
        if (index >= 1000 && index < 1100) {
            EXPECT_NE(std::find(childSample.begin(), childSample.end(), index), childSample.end());
        }
    }
    // Taking all points returns the concatenation itself.
    std::vector<std::uint32_t> all(40);
    sampleChildren(children, all);
    EXPECT_EQ(all[20], 1000u);
    EXPECT_EQ(all[39], 5009u);
}

// A parent whose children hold their whole ranges keeps its sample implicit (the builder stores
// no indices for it): its held points must be exactly the picks sampleChildren stores, and a
// grandparent must draw the same sample from it as from the stored list.
TEST(ParentSampler, ImplicitSamplesEqualTheStoredOnes) {
    const std::array<std::uint32_t, 5> sizes = {7, 1, 30, 12, 3};
    std::array<OctreeNode, 5> leaves{};
    std::uint32_t next = 100;
    for (std::size_t c = 0; c < sizes.size(); ++c) {
        leaves[c].coveredBegin = next;
        leaves[c].pointCount = leaves[c].coveredCount = sizes[c];
        next += sizes[c];
    }
    std::array<const OctreeNode*, 5> children{};
    for (std::size_t c = 0; c < leaves.size(); ++c) {
        children[c] = &leaves[c];
    }
    for (double ratio : {0.01, 0.2, 0.25, 0.5, 0.9, 1.0}) {
        OctreeNode implicit;
        implicit.coveredBegin = 100;
        implicit.coveredCount = next - 100;
        implicit.pointCount = sampleSize(implicit.coveredCount, ratio);
        ASSERT_EQ(implicit.holdsImplicitSample(), implicit.pointCount < implicit.coveredCount);
        std::vector<std::uint32_t> stored(implicit.pointCount);
        sampleChildren(children, stored);
        for (std::uint32_t i = 0; i < implicit.pointCount; ++i) {
            ASSERT_EQ(implicit.heldPoint(i), stored[i]) << "ratio " << ratio << " pick " << i;
        }

        // The same parent with its list stored, beside a range sibling and a stored sibling.
        OctreeNode storedParent = implicit;
        storedParent.sampleIndices = stored.data();
        OctreeNode rangeSibling;
        rangeSibling.coveredBegin = next;
        rangeSibling.pointCount = rangeSibling.coveredCount = 9;
        const std::vector<std::uint32_t> siblingList = {next + 10, next + 14, next + 15};
        OctreeNode storedSibling;
        storedSibling.sampleIndices = siblingList.data();
        storedSibling.coveredBegin = next + 9;
        storedSibling.coveredCount = 20;
        storedSibling.pointCount = 3;
        const std::uint64_t points = implicit.pointCount + 9 + 3;
        for (double upper : {0.1, 0.3, 1.0}) {
            std::vector<std::uint32_t> fromImplicit(sampleSize(points, upper));
            std::vector<std::uint32_t> fromStored(fromImplicit.size());
            const std::array<const OctreeNode*, 3> a = {&implicit, &rangeSibling, &storedSibling};
            const std::array<const OctreeNode*, 3> b = {&storedParent, &rangeSibling,
                                                        &storedSibling};
            sampleChildren(a, fromImplicit);
            sampleChildren(b, fromStored);
            ASSERT_EQ(fromImplicit, fromStored) << "ratio " << ratio << " upper " << upper;
        }
    }
}

// Clouds of up to 2^32 - 1 points: (2i + 1) n no longer fits 64 bits, and picks stay exact, in
// OctreeNode::heldPoint and through an implicit child alike.
TEST(ParentSampler, PicksAreExactForTheLargestCounts) {
    const std::uint64_t n = 0xffffffffull, count = n - 1;
    EXPECT_EQ(stratifiedPick(0, n, count), 0u);
    EXPECT_EQ(stratifiedPick(count - 1, n, count), n - 1); // floor(n - n / 2count)
    EXPECT_EQ(stratifiedPick(count / 2, n, count), count / 2 + 1);

    OctreeNode huge;
    huge.coveredBegin = 0;
    huge.coveredCount = 4000000000u;
    huge.pointCount = 3000000000u;
    ASSERT_TRUE(huge.holdsImplicitSample());
    std::vector<std::uint32_t> out(1000);
    const std::array<const OctreeNode*, 1> children = {&huge};
    sampleChildren(children, out);
    for (std::uint32_t j = 0; j < out.size(); ++j) {
        const auto position = static_cast<std::uint32_t>(stratifiedPick(j, huge.pointCount, 1000));
        ASSERT_EQ(out[j], huge.heldPoint(position)) << "pick " << j;
    }
    EXPECT_EQ(huge.heldPoint(huge.pointCount - 1), 3999999999u);
}

} // namespace
} // namespace omicron
