// The preview's reservoir: a uniform sample of everything added, the same whatever the batches.
#include "sort/preview_sampler.hpp"

#include <algorithm>
#include <array>
#include <gtest/gtest.h>
#include <set>

namespace omicron {
namespace {

// Points whose x is their index (exact in a float below 2^24), added in batches of `batch`.
PreviewSample sampleOf(std::size_t points, std::size_t batch, std::size_t capacity,
                       std::uint64_t seed) {
    PreviewSampler sampler(capacity, seed);
    for (std::size_t first = 0; first < points; first += batch) {
        PointBatch next;
        next.attributes = AttributeSet{} | Attribute::Color;
        for (std::size_t i = first; i < std::min(points, first + batch); ++i) {
            next.positions.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
            next.colors.emplace_back(static_cast<std::uint8_t>(i), 0, 0);
        }
        sampler.add(next, first);
    }
    return sampler.sample();
}

TEST(PreviewSampler, KeepsEveryPointWhileTheReservoirIsNotFull) {
    const PreviewSample sample = sampleOf(700, 300, 1000, 7);
    ASSERT_EQ(sample.positions.size(), 700u);
    for (std::size_t i = 0; i < 700; ++i) {
        EXPECT_EQ(sample.positions[i].x, static_cast<float>(i));
    }
    EXPECT_EQ(sample.pointsSeen, 700u);
}

// Each of 200,000 points is equally likely to be among the 2,000 kept: the kept indices fall
// evenly into ten equal ranges (chi-square of 9 degrees of freedom below its 0.1 % point), are
// distinct, and keep their own colour.
TEST(PreviewSampler, EveryPointIsEquallyLikely) {
    constexpr std::size_t kPoints = 200'000, kCapacity = 2'000;
    const PreviewSample sample = sampleOf(kPoints, 7'000, kCapacity, 0x9e3779b97f4a7c15ull);
    ASSERT_EQ(sample.positions.size(), kCapacity);
    EXPECT_EQ(sample.pointsSeen, kPoints);
    std::array<double, 10> counts{};
    std::set<std::size_t> kept;
    for (std::size_t i = 0; i < kCapacity; ++i) {
        const auto index = static_cast<std::size_t>(sample.positions[i].x);
        ASSERT_LT(index, kPoints);
        EXPECT_EQ(sample.colors[i].r, static_cast<std::uint8_t>(index));
        kept.insert(index);
        counts[index * counts.size() / kPoints] += 1.0;
    }
    EXPECT_EQ(kept.size(), kCapacity);
    const double expected = static_cast<double>(kCapacity) / counts.size();
    double chiSquare = 0.0;
    for (const double count : counts) {
        chiSquare += (count - expected) * (count - expected) / expected;
    }
    EXPECT_LT(chiSquare, 27.88);
}

// The draws do not depend on where batches end: the same points in other batches give the same
// sample, and another seed another one.
TEST(PreviewSampler, TheSampleDoesNotDependOnTheBatches) {
    const PreviewSample a = sampleOf(50'000, 65'536, 500, 11);
    const PreviewSample b = sampleOf(50'000, 333, 500, 11);
    const PreviewSample c = sampleOf(50'000, 333, 500, 12);
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_NE(a.positions, c.positions);
}

} // namespace
} // namespace omicron
