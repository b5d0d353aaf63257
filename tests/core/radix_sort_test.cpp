// The parallel radix sort against std::stable_sort, for sizes, key shapes and thread counts.
#include "radix_sort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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
                      KeyShape{"large_full", 1000000, ~0ull}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(RadixSort, AllEqualKeysKeepInputOrder) {
    const std::vector<std::uint64_t> keys(100000, 0x8000000000000123ull);
    const Sorted sorted = radixSorted(keys);
    for (std::uint32_t i = 0; i < sorted.values.size(); ++i) {
        ASSERT_EQ(sorted.values[i], i);
    }
}

TEST(RadixSort, AlreadySortedAndReversedInput) {
    std::vector<std::uint64_t> ascending(300000);
    std::iota(ascending.begin(), ascending.end(), std::uint64_t{1} << 63);
    EXPECT_EQ(radixSorted(ascending), referenceSorted(ascending));
    std::vector<std::uint64_t> descending(ascending.rbegin(), ascending.rend());
    EXPECT_EQ(radixSorted(descending), referenceSorted(descending));
}

TEST(RadixSort, SameResultForOneAndManyThreads) {
    const auto keys = randomKeys(700000, 0xffff0000ffffull, 5);
    Sorted one, many;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = radixSorted(keys);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 4);
        many = radixSorted(keys);
    }
    EXPECT_EQ(one, many);
    EXPECT_TRUE(std::is_sorted(one.keys.begin(), one.keys.end()));
}

} // namespace
} // namespace omicron
