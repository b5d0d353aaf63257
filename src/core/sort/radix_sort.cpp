#include "sort/radix_sort.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <functional>
#include <memory>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <vector>

namespace omicron {

namespace {

// The constants were tuned on the level-21 codes of autzen_south (4.8M keys, the data of
// bench/sort_bench) on 2 cores with 1 MiB L2 each, sweeping each around its value.

// Tiny groups are finished by insertion sort; larger ones get another radix step.
constexpr std::size_t kInsertionSortMax = 16;
// From this size on a range is distributed by all threads (keys, values and scratch exceed an
// L2 cache); below it one thread sorts it in cache.
constexpr std::size_t kParallelMin = std::size_t{1} << 16;
// Fixed block size for the parallel histograms: a function of the data size only, so the
// output never depends on the thread count.
constexpr std::size_t kBlockKeys = std::size_t{1} << 18;
// The parallel digit aims at buckets of about 2^11 keys (cache-resident) but is at most 14
// bits wide (best of 10..16): wider ones cost more in counters and write streams than the
// smaller buckets save.
constexpr int kLargeBucketBits = 11;
constexpr int kLargeDigitMaxWidth = 14;
// Digits of the in-cache steps: up to 12 bits, so that their two counter arrays (32 KiB) stay
// in the L1 cache.
constexpr int kCachedDigitMaxWidth = 12;
// Recursion depth bound: every step consumes at least one of the 64 key bits.
constexpr int kMaxDepth = 64;

struct Range {
    std::uint64_t* keys;
    std::uint32_t* values;
    std::uint64_t* keyScratch;
    std::uint32_t* valueScratch;
    std::size_t count;

    Range sub(std::size_t begin, std::size_t size) const {
        return {keys + begin, values + begin, keyScratch + begin, valueScratch + begin, size};
    }
    Range swapped() const { return {keyScratch, valueScratch, keys, values, count}; }
};

void insertionSort(std::uint64_t* keys, std::uint32_t* values, std::size_t count) {
    for (std::size_t i = 1; i < count; ++i) {
        const std::uint64_t key = keys[i];
        if (keys[i - 1] <= key) {
            continue;
        }
        const std::uint32_t value = values[i];
        std::size_t j = i;
        do {
            keys[j] = keys[j - 1];
            values[j] = values[j - 1];
            --j;
        } while (j > 0 && keys[j - 1] > key); // strict: equal keys stay in order
        keys[j] = key;
        values[j] = value;
    }
}

// Bits in which some key differs from the first one.
std::uint64_t varyingBits(const std::uint64_t* keys, std::size_t count) {
    const std::uint64_t first = keys[0];
    const auto orDiffs = [&](std::size_t begin, std::size_t end, std::uint64_t bits) {
        for (std::size_t i = begin; i < end; ++i) {
            bits |= keys[i] ^ first;
        }
        return bits;
    };
    if (count < kParallelMin) {
        return orDiffs(0, count, 0);
    }
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, count, kBlockKeys / 4), std::uint64_t{0},
        [&](const tbb::blocked_range<std::size_t>& block, std::uint64_t bits) {
            return orDiffs(block.begin(), block.end(), bits);
        },
        std::bit_or<>());
}

// The bits [shift, shift + width) of a key.
struct Digit {
    int shift;
    int width;

    std::size_t digits() const { return std::size_t{1} << width; }
    std::size_t of(std::uint64_t key) const {
        return static_cast<std::size_t>((key >> shift) & ((std::uint64_t{1} << width) - 1));
    }
};

// The digit that starts at the highest varying bit and reaches down until it covers
// `varyingWanted` varying bits or is `maxWidth` wide; constant bits at its bottom are dropped.
// Bits above it are equal in all keys, so it is the most significant digit that splits them.
// Morton codes of surfaces (a constant axis bit every third bit) get a wider window this way.
Digit highestDigit(std::uint64_t varying, int varyingWanted, int maxWidth) {
    assert(varying != 0);
    const int top = 64 - std::countl_zero(varying);
    int width = 0;
    int covered = 0;
    while (width < maxWidth && width < top && covered < varyingWanted) {
        ++width;
        covered += static_cast<int>((varying >> (top - width)) & 1);
    }
    const int shift = top - width;
    const int constantBottom =
        std::countr_zero((varying >> shift) & ((std::uint64_t{1} << width) - 1));
    return {shift + constantBottom, width - constantBottom};
}

// Per-thread counter arrays of the in-cache steps, one per recursion depth, so that a step's
// counters stay valid while deeper steps use theirs. In-cache steps never wait on other tasks,
// so no other sort can interleave with them on the same thread.
std::uint32_t* countersAt(int depth, std::size_t size) {
    struct Level {
        std::unique_ptr<std::uint32_t[]> counters;
        std::size_t size = 0;
    };
    thread_local std::array<Level, kMaxDepth + 1> levels;
    Level& level = levels[static_cast<std::size_t>(depth)];
    if (level.size < size) {
        level.counters = std::make_unique<std::uint32_t[]>(size);
        level.size = size;
    }
    return level.counters.get();
}

// Turns counts into starting offsets.
void exclusivePrefix(std::uint32_t* counts, std::size_t digits) {
    std::uint32_t offset = 0;
    for (std::size_t d = 0; d < digits; ++d) {
        const std::uint32_t n = counts[d];
        counts[d] = offset;
        offset += n;
    }
}

// Stable counting scatter of keys/values by `digit`, advancing each digit's `cursor`.
void scatter(const std::uint64_t* keys, const std::uint32_t* values, std::size_t begin,
             std::size_t end, Digit digit, std::uint32_t* cursor, std::uint64_t* keysOut,
             std::uint32_t* valuesOut) {
    for (std::size_t i = begin; i < end; ++i) {
        const std::uint64_t key = keys[i];
        const std::uint32_t to = cursor[digit.of(key)]++;
        keysOut[to] = key;
        valuesOut[to] = values[i];
    }
}

void sortInPlace(const Range& r);

// Sorts a cache-resident range in place (r.keys; r.keyScratch is the scratch). The highest
// two digits below the common prefix are sorted least significant first, by two stable
// scatters there and back, which for the data of a point cloud leaves hardly any equal keys
// under those 24 bits. Keys that agree on every bit down to the low digit's shift (few, and
// in input order) form groups that are finished one by one: insertion sort for a handful,
// the same procedure on the remaining bits for more.
void sortCached(const Range& r, int depth) {
    const std::size_t count = r.count;
    if (count <= kInsertionSortMax) {
        insertionSort(r.keys, r.values, count);
        return;
    }
    const std::uint64_t varying = varyingBits(r.keys, count);
    if (varying == 0) {
        return; // all keys equal: already in (stable) order
    }
    // Digits about as wide as log2(count): ample for few keys, at most L1-sized counters.
    const int width = std::min(static_cast<int>(std::bit_width(count)), kCachedDigitMaxWidth);
    const Digit high = highestDigit(varying, width, width);
    const std::uint64_t below = varying & ((std::uint64_t{1} << high.shift) - 1);
    if (below == 0) {
        // One digit holds every varying bit: a single scatter sorts the keys completely.
        std::uint32_t* cursor = countersAt(depth, high.digits());
        std::fill_n(cursor, high.digits(), 0u);
        for (std::size_t i = 0; i < count; ++i) {
            ++cursor[high.of(r.keys[i])];
        }
        exclusivePrefix(cursor, high.digits());
        scatter(r.keys, r.values, 0, count, high, cursor, r.keyScratch, r.valueScratch);
        std::copy_n(r.keyScratch, count, r.keys);
        std::copy_n(r.valueScratch, count, r.values);
        return;
    }
    // Constant bits between the two digits do not matter to the order.
    const Digit low = highestDigit(below, width, width);
    std::uint32_t* highCursor = countersAt(depth, high.digits() + low.digits());
    std::uint32_t* lowCursor = highCursor + high.digits();
    std::fill_n(highCursor, high.digits() + low.digits(), 0u);
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint64_t key = r.keys[i];
        ++highCursor[high.of(key)];
        ++lowCursor[low.of(key)];
    }
    exclusivePrefix(highCursor, high.digits());
    exclusivePrefix(lowCursor, low.digits());
    scatter(r.keys, r.values, 0, count, low, lowCursor, r.keyScratch, r.valueScratch);
    scatter(r.keyScratch, r.valueScratch, 0, count, high, highCursor, r.keys, r.values);
    // Now sorted by key >> low.shift; finish the groups that share it.
    const int shift = low.shift;
    if (shift == 0) {
        return;
    }
    std::size_t groupBegin = 0;
    std::uint64_t groupPrefix = r.keys[0] >> shift;
    for (std::size_t i = 1; i <= count; ++i) {
        const std::uint64_t prefix = i < count ? r.keys[i] >> shift : ~groupPrefix;
        if (prefix == groupPrefix) {
            continue;
        }
        const std::size_t size = i - groupBegin;
        if (size > kInsertionSortMax) {
            sortCached(r.sub(groupBegin, size), depth + 1);
        } else if (size > 1) {
            insertionSort(r.keys + groupBegin, r.values + groupBegin, size);
        }
        groupBegin = i;
        groupPrefix = prefix;
    }
}

// Stable parallel scatter of r.keys into r.keyScratch by `digit`: per block of keys (fixed by
// the count, not the threads) a histogram, an exclusive prefix in (digit, block) order so
// that equal digits keep their block order, then every block scatters on its own. Returns
// where each bucket starts, plus the end. Plain scatters: software write-combining buffers
// measured slower here, as the live buckets (about 900 for autzen_south) keep few enough write
// streams for the caches and TLB.
std::vector<std::size_t> distributeInParallel(const Range& r, Digit digit) {
    const std::size_t digits = digit.digits();
    const std::size_t blocks = (r.count + kBlockKeys - 1) / kBlockKeys;
    const std::size_t blockSize = (r.count + blocks - 1) / blocks;
    // counts[block * digits + digit]: first a histogram, then the block's write cursor.
    std::vector<std::uint32_t> counts(blocks * digits, 0);
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
        std::uint32_t* histogram = counts.data() + block * digits;
        const std::size_t end = std::min(r.count, (block + 1) * blockSize);
        for (std::size_t i = block * blockSize; i < end; ++i) {
            ++histogram[digit.of(r.keys[i])];
        }
    });
    // The prefix runs block row by block row, reading the counters in memory order.
    std::vector<std::uint32_t> cursor(digits, 0);
    for (std::size_t block = 0; block < blocks; ++block) {
        const std::uint32_t* histogram = counts.data() + block * digits;
        for (std::size_t d = 0; d < digits; ++d) {
            cursor[d] += histogram[d];
        }
    }
    exclusivePrefix(cursor.data(), digits);
    std::vector<std::size_t> bucketBegin(cursor.begin(), cursor.end());
    bucketBegin.push_back(r.count);
    for (std::size_t block = 0; block < blocks; ++block) {
        std::uint32_t* histogram = counts.data() + block * digits;
        for (std::size_t d = 0; d < digits; ++d) {
            const std::uint32_t n = histogram[d];
            histogram[d] = cursor[d];
            cursor[d] += n;
        }
    }
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
        scatter(r.keys, r.values, block * blockSize, std::min(r.count, (block + 1) * blockSize),
                digit, counts.data() + block * digits, r.keyScratch, r.valueScratch);
    });
    return bucketBegin;
}

// Scatters a large range `r` (varying bits `varying`) into r.keyScratch/valueScratch by a top
// digit wide enough for cache-sized buckets, then sorts every bucket in parallel with
// sortBucket(bucket) (the bucket's keys sit in its scratch arrays).
template <typename SortBucket>
void distributeAndSortBuckets(const Range& r, std::uint64_t varying, SortBucket&& sortBucket) {
    const Digit digit = highestDigit(
        varying, std::max(static_cast<int>(std::bit_width(r.count)) - kLargeBucketBits, 1),
        kLargeDigitMaxWidth);
    const std::vector<std::size_t> bucketBegin = distributeInParallel(r, digit);
    tbb::parallel_for(std::size_t{0}, bucketBegin.size() - 1, [&](std::size_t d) {
        const std::size_t begin = bucketBegin[d];
        const std::size_t size = bucketBegin[d + 1] - begin;
        if (size > 0) {
            sortBucket(r.sub(begin, size));
        }
    });
}

// Sorts from.keys/values into into.keys/values (same count); from's arrays serve as scratch.
void sortInto(const Range& from, const Range& into) {
    const std::size_t count = from.count;
    const Range r{from.keys, from.values, into.keys, into.values, count};
    const auto copyOver = [&] {
        std::copy_n(from.keys, count, into.keys);
        std::copy_n(from.values, count, into.values);
    };
    if (count < kParallelMin) {
        copyOver(); // a cheap pass in cache, and the in-cache sort works in place
        sortCached(r.swapped(), 0);
        return;
    }
    const std::uint64_t varying = varyingBits(from.keys, count);
    if (varying == 0) {
        copyOver();
        return;
    }
    // A bucket sits in `into`'s arrays now, which its in-place sort keeps it in.
    distributeAndSortBuckets(r, varying,
                             [](const Range& bucket) { sortInPlace(bucket.swapped()); });
}

// Sorts r.keys/values in place; r.keyScratch/valueScratch serve as scratch.
void sortInPlace(const Range& r) {
    const std::size_t count = r.count;
    if (count < kParallelMin) {
        sortCached(r, 0);
        return;
    }
    const std::uint64_t varying = varyingBits(r.keys, count);
    if (varying == 0) {
        return;
    }
    // Each bucket now sits in the scratch arrays; sorting it writes it back into place.
    distributeAndSortBuckets(r, varying,
                             [](const Range& bucket) { sortInto(bucket.swapped(), bucket); });
}

} // namespace

void radixSortByKey(std::span<std::uint64_t> keys, std::span<std::uint32_t> values,
                    std::span<std::uint64_t> keyScratch, std::span<std::uint32_t> valueScratch) {
    assert(keys.size() == values.size());
    assert(keyScratch.size() >= keys.size() && valueScratch.size() >= values.size());
    assert(keys.size() <= UINT32_MAX);
    if (keys.size() < 2) {
        return;
    }
    sortInPlace({keys.data(), values.data(), keyScratch.data(), valueScratch.data(), keys.size()});
}

} // namespace omicron
