// The parallel radix sort against std::stable_sort, for sizes, key shapes and thread counts.
// The shapes reach every path: the parallel distribution (over 2^16 keys, also nested when one
// bucket is that large again), the in-cache two-digit sort with its groups finished by
// insertion sort (up to 16 keys) or by another step (17 and more), and the single digit that
// holds every varying bit.
#include "io/point_reader.hpp"
#include "points/morton.hpp"
#include "sort/radix_sort.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <numeric>
#include <random>
#include <tbb/global_control.h>
#include <vector>

namespace omicron {
namespace {

struct Sorted {
    std::vector<std::uint64_t> keys;
    std::vector<std::uint32_t> values;
    friend bool operator==(const Sorted&, const Sorted&) = default;
};

Sorted radixSorted(std::vector<std::uint64_t> keys) {
    std::vector<std::uint32_t> values(keys.size());
    std::iota(values.begin(), values.end(), 0u);
    std::vector<std::uint64_t> keyScratch(keys.size());
    std::vector<std::uint32_t> valueScratch(keys.size());
    radixSortByKey(keys, values, keyScratch, valueScratch);
    return {keys, values};
}

Sorted referenceSorted(const std::vector<std::uint64_t>& keys) {
    std::vector<std::uint32_t> order(keys.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
    Sorted sorted;
    for (std::uint32_t i : order) {
        sorted.keys.push_back(keys[i]);
        sorted.values.push_back(i);
    }
    return sorted;
}

std::vector<std::uint64_t> randomKeys(std::size_t count, std::uint64_t mask, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    std::vector<std::uint64_t> keys(count);
    for (auto& key : keys) {
        key = random() & mask;
    }
    return keys;
}

// Level-21 Morton codes of points on a wavy surface: two axes spread, the third a function of
// them, like an aerial scan (every third code bit nearly constant).
std::vector<std::uint64_t> surfaceCodes(std::size_t count, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<std::uint64_t> keys(count);
    for (auto& key : keys) {
        const float x = unit(random);
        const float y = unit(random);
        const float z = 0.5f + 0.05f * std::sin(20.0f * x) * std::cos(13.0f * y);
        key = morton::encodeUnit(x, y, z);
    }
    return keys;
}

struct KeyShape {
    const char* name;
    std::size_t count;
    std::uint64_t mask;
};

class RadixSortShapes : public ::testing::TestWithParam<KeyShape> {};

TEST_P(RadixSortShapes, MatchesStableSortAndIsStable) {
    const KeyShape shape = GetParam();
    const auto keys = randomKeys(shape.count, shape.mask, shape.count * 31 + shape.mask);
    EXPECT_EQ(radixSorted(keys), referenceSorted(keys));
}

INSTANTIATE_TEST_SUITE_P(
    Shapes, RadixSortShapes,
    ::testing::Values(KeyShape{"empty", 0, ~0ull}, KeyShape{"single", 1, ~0ull},
                      KeyShape{"pair", 2, ~0ull}, KeyShape{"small_full", 1000, ~0ull},
                      KeyShape{"many_duplicates", 200000, 0xffull},
                      KeyShape{"only_high_bits", 150000, 0xfff0000000000000ull},
                      KeyShape{"only_low_bits", 150000, 0x7ffull},
                      KeyShape{"middle_bits", 150000, 0x0000ffff00000000ull},
                      KeyShape{"one_cached_digit", 5000, 0x3ffull},
                      KeyShape{"cached_far_apart_bits", 40000, 0xc000000300000fffull},
                      KeyShape{"parallel_far_apart_bits", 1100000, 0xc000000300000fffull},
                      KeyShape{"parallel_low_bits", (1u << 20) + 5, 0xfffffull},
                      KeyShape{"large_full", 1000000, ~0ull}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(RadixSort, AllEqualKeysKeepInputOrder) {
    for (std::size_t count : {std::size_t{17}, std::size_t{100000}, (std::size_t{1} << 20) + 3}) {
        const std::vector<std::uint64_t> keys(count, 0x8000000000000123ull);
        const Sorted sorted = radixSorted(keys);
        for (std::uint32_t i = 0; i < sorted.values.size(); ++i) {
            ASSERT_EQ(sorted.values[i], i) << count << " keys";
        }
    }
}

TEST(RadixSort, SurfaceMortonCodes) {
    for (std::size_t count : {std::size_t{300}, std::size_t{20000}, std::size_t{700000}}) {
        const auto keys = surfaceCodes(count, count);
        EXPECT_EQ(radixSorted(keys), referenceSorted(keys)) << count << " keys";
    }
}

// Groups of keys that agree on both in-cache digits (bits 60-61 and 30-31 here) and differ
// below them: 16 per group goes to insertion sort, 17 to a further step, several hundred to
// a further step that again leaves groups.
TEST(RadixSort, GroupsBelowTheCachedDigits) {
    std::mt19937_64 random(11);
    for (std::size_t groupSize : {std::size_t{16}, std::size_t{17}, std::size_t{600}}) {
        std::vector<std::uint64_t> keys;
        for (std::uint64_t group = 0; group < 16; ++group) {
            const std::uint64_t prefix = (group >> 2) << 60 | (group & 3) << 30;
            for (std::size_t i = 0; i < groupSize + group % 2; ++i) {
                keys.push_back(prefix | (random() & 0x300fffull));
            }
        }
        std::shuffle(keys.begin(), keys.end(), random);
        EXPECT_EQ(radixSorted(keys), referenceSorted(keys)) << groupSize << " keys per group";
    }
}

// One bucket of the parallel distribution is itself over the parallel threshold.
TEST(RadixSort, NestedParallelBuckets) {
    std::mt19937_64 random(3);
    std::vector<std::uint64_t> keys(900000);
    for (std::size_t i = 0; i < keys.size(); ++i) {
        keys[i] = i % 5 == 0 ? random() : 0x8123400000000000ull | (random() & 0xffffffull);
    }
    EXPECT_EQ(radixSorted(keys), referenceSorted(keys));
}

// A bucket of the parallel distribution that is over the threshold and holds one key only.
TEST(RadixSort, LargeBucketOfEqualKeys) {
    std::mt19937_64 random(4);
    std::vector<std::uint64_t> keys(400000);
    for (std::size_t i = 0; i < keys.size(); ++i) {
        keys[i] = i % 2 == 0 ? 0x8000000000000123ull : random();
    }
    EXPECT_EQ(radixSorted(keys), referenceSorted(keys));
}

TEST(RadixSort, HeavyDuplicatesOverTheParallelThreshold) {
    std::mt19937_64 random(9);
    std::vector<std::uint64_t> keys(1200000);
    for (auto& key : keys) {
        key = random() & 0xf000000000000003ull;
    }
    EXPECT_EQ(radixSorted(keys), referenceSorted(keys));
}

TEST(RadixSort, AlreadySortedAndReversedInput) {
    std::vector<std::uint64_t> ascending(300000);
    std::iota(ascending.begin(), ascending.end(), std::uint64_t{1} << 63);
    EXPECT_EQ(radixSorted(ascending), referenceSorted(ascending));
    std::vector<std::uint64_t> descending(ascending.rbegin(), ascending.rend());
    EXPECT_EQ(radixSorted(descending), referenceSorted(descending));
}

// The same unique stable order for 1, 2 and 4 threads, on inputs that take the parallel
// paths (nested buckets included).
TEST(RadixSort, SameResultForOneTwoAndFourThreads) {
    std::vector<std::uint64_t> keys = surfaceCodes(1500000, 5);
    std::mt19937_64 random(5);
    for (std::size_t i = 0; i < 300000; ++i) {
        keys[random() % keys.size()] = 0x8000000000000000ull | (random() & 0xffffull);
    }
    const Sorted expected = referenceSorted(keys);
    for (int threads : {1, 2, 4}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        EXPECT_EQ(radixSorted(keys), expected) << threads << " threads";
    }
}

// The codes of a real scan, as the sorter and sort_bench sort them.
TEST(RadixSort, RealScanCodesForOneTwoAndFourThreads) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.ply");
    const LoadedCloud cloud = loadPointCloud(path);
    std::vector<std::uint64_t> keys(cloud.points.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
        const auto& p = cloud.points.positions[i];
        keys[i] = morton::encodeUnit(p.x, p.y, p.z);
    }
    const Sorted expected = referenceSorted(keys);
    for (int threads : {1, 2, 4}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        EXPECT_EQ(radixSorted(keys), expected) << threads << " threads";
    }
}

} // namespace
} // namespace omicron
