#include "radix_sort.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <functional>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <vector>

namespace omicron {

namespace {

constexpr std::size_t kInsertionSortMax = 32;
// Below this a range is sorted by one thread: spawning tasks would cost more than it saves.
constexpr std::size_t kParallelMin = std::size_t{1} << 16;
// Fixed block size for parallel histograms: a function of the data size only.
constexpr std::size_t kBlockKeys = std::size_t{1} << 15;

struct Range {
    std::uint64_t* keys;
    std::uint32_t* values;
    std::uint64_t* keyScratch;
    std::uint32_t* valueScratch;
    std::size_t count;

    Range sub(std::size_t begin, std::size_t size) const {
        return {keys + begin, values + begin, keyScratch + begin, valueScratch + begin, size};
    }
};

void insertionSort(const Range& r) {
    for (std::size_t i = 1; i < r.count; ++i) {
        const std::uint64_t key = r.keys[i];
        const std::uint32_t value = r.values[i];
        std::size_t j = i;
        for (; j > 0 && r.keys[j - 1] > key; --j) { // strict: equal keys stay in order
            r.keys[j] = r.keys[j - 1];
            r.values[j] = r.values[j - 1];
        }
        r.keys[j] = key;
        r.values[j] = value;
    }
}

// Bits in which some key differs from the first one.
std::uint64_t varyingBits(const Range& r) {
    const std::uint64_t first = r.keys[0];
    const auto orDiffs = [&](std::size_t begin, std::size_t end, std::uint64_t bits) {
        for (std::size_t i = begin; i < end; ++i) {
            bits |= r.keys[i] ^ first;
        }
        return bits;
    };
    if (r.count < kParallelMin) {
        return orDiffs(0, r.count, 0);
    }
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, r.count, kBlockKeys), std::uint64_t{0},
        [&](const tbb::blocked_range<std::size_t>& b, std::uint64_t bits) {
            return orDiffs(b.begin(), b.end(), bits);
        },
        std::bit_or<>());
}

// Stable counting scatter of r.keys/values into r.keyScratch/valueScratch by the digit
// (key >> shift) & (digits - 1). Returns where each bucket starts, plus the end; returns an
// empty vector, having moved nothing, when every key has the same digit.
std::vector<std::size_t> scatterByDigit(const Range& r, int shift, std::size_t digits) {
    const std::uint64_t mask = digits - 1;
    const auto digitOf = [&](std::uint64_t key) {
        return static_cast<std::size_t>((key >> shift) & mask);
    };
    const std::size_t blocks = r.count < kParallelMin ? 1 : (r.count + kBlockKeys - 1) / kBlockKeys;
    const std::size_t blockSize = (r.count + blocks - 1) / blocks;
    // counts[block * digits + digit]: first a histogram, then the block's write cursor.
    std::vector<std::size_t> counts(blocks * digits, 0);
    const auto forEachBlock = [&](auto&& body) {
        if (blocks == 1) {
            body(std::size_t{0});
        } else {
            tbb::parallel_for(std::size_t{0}, blocks, body);
        }
    };
    forEachBlock([&](std::size_t block) {
        std::size_t* histogram = counts.data() + block * digits;
        const std::size_t end = std::min(r.count, (block + 1) * blockSize);
        for (std::size_t i = block * blockSize; i < end; ++i) {
            ++histogram[digitOf(r.keys[i])];
        }
    });
    // Exclusive prefix in (digit, block) order: equal digits keep their block order (stable).
    std::vector<std::size_t> bucketBegin(digits + 1, 0);
    std::size_t offset = 0;
    for (std::size_t digit = 0; digit < digits; ++digit) {
        bucketBegin[digit] = offset;
        for (std::size_t block = 0; block < blocks; ++block) {
            const std::size_t n = counts[block * digits + digit];
            if (n == r.count) {
                return {};
            }
            counts[block * digits + digit] = offset;
            offset += n;
        }
    }
    bucketBegin[digits] = offset;
    forEachBlock([&](std::size_t block) {
        std::size_t* cursor = counts.data() + block * digits;
        const std::size_t end = std::min(r.count, (block + 1) * blockSize);
        for (std::size_t i = block * blockSize; i < end; ++i) {
            const std::size_t to = cursor[digitOf(r.keys[i])]++;
            r.keyScratch[to] = r.keys[i];
            r.valueScratch[to] = r.values[i];
        }
    });
    return bucketBegin;
}

void sortInto(const Range& from, const Range& into, int topBit);

// Digit width: large ranges (scattered across memory by all threads) use 8 bits, so 256
// write streams stay cache- and TLB-friendly; cache-resident ranges use up to 11 bits, sized
// so that buckets come out small enough for insertion sort (measured in bench/sort_bench:
// fewer levels beat smaller histograms there).
int digitBitsFor(std::size_t count) {
    if (count >= kParallelMin) {
        return 8;
    }
    return std::clamp(static_cast<int>(std::bit_width(count)) - 4, 3, 11);
}

// Finds the digit to distribute `r` by, knowing every key agrees on the bits at and above
// `topBit`, and scatters r.keys into r.keyScratch by it. Small ranges first find the highest
// varying bit (one pass in cache); large ones skip that full pass and try digits from the top,
// a digit on which all keys agree costing only its histogram. Returns the bucket starts and
// the digit's shift, or no buckets when all keys are equal.
std::pair<std::vector<std::size_t>, int> distribute(const Range& r, int topBit) {
    if (r.count < kParallelMin) {
        const std::uint64_t below = topBit >= 64 ? ~0ull : (std::uint64_t{1} << topBit) - 1;
        const std::uint64_t varying = varyingBits(r) & below;
        if (varying == 0) {
            return {};
        }
        topBit = 64 - std::countl_zero(varying);
    }
    while (topBit > 0) {
        const int digitBits = std::min(digitBitsFor(r.count), topBit);
        const int shift = topBit - digitBits;
        std::vector<std::size_t> buckets = scatterByDigit(r, shift, std::size_t{1} << digitBits);
        if (!buckets.empty()) {
            return {std::move(buckets), shift};
        }
        topBit = shift;
    }
    return {};
}

template <typename Body> void forEachBucket(std::size_t count, std::size_t buckets, Body&& body) {
    if (count >= kParallelMin) {
        tbb::parallel_for(std::size_t{0}, buckets, body);
    } else {
        for (std::size_t bucket = 0; bucket < buckets; ++bucket) {
            body(bucket);
        }
    }
}

// Sorts the keys of `r` in place (r.keys/values), using r.keyScratch/valueScratch.
void sortInPlace(const Range& r, int topBit) {
    if (r.count <= kInsertionSortMax) {
        insertionSort(r);
        return;
    }
    const auto [bucketBegin, shift] = distribute(r, topBit);
    if (bucketBegin.empty()) {
        return; // all keys equal: already in (stable) order
    }
    // Each bucket now sits in the scratch arrays; sorting it writes it back into place, so
    // no level copies the data back separately.
    forEachBucket(r.count, bucketBegin.size() - 1, [&](std::size_t digit) {
        const std::size_t begin = bucketBegin[digit];
        const std::size_t size = bucketBegin[digit + 1] - begin;
        if (size > 0) {
            const Range bucket = r.sub(begin, size);
            sortInto({bucket.keyScratch, bucket.valueScratch, bucket.keys, bucket.values, size},
                     bucket, shift);
        }
    });
}

// Sorts the keys held in from.keys/values into into.keys/values (same count); the arrays of
// `from` serve as scratch.
void sortInto(const Range& from, const Range& into, int topBit) {
    const auto finishInInto = [&] {
        std::copy_n(from.keys, from.count, into.keys);
        std::copy_n(from.values, from.count, into.values);
        insertionSort(into); // linear when the keys are already in order
    };
    if (from.count <= kInsertionSortMax) {
        finishInInto();
        return;
    }
    const auto [bucketBegin, shift] =
        distribute({from.keys, from.values, into.keys, into.values, from.count}, topBit);
    if (bucketBegin.empty()) {
        finishInInto();
        return;
    }
    forEachBucket(from.count, bucketBegin.size() - 1, [&](std::size_t digit) {
        const std::size_t begin = bucketBegin[digit];
        const std::size_t size = bucketBegin[digit + 1] - begin;
        if (size > 0) {
            sortInPlace({into.keys + begin, into.values + begin, from.keys + begin,
                         from.values + begin, size},
                        shift);
        }
    });
}

} // namespace

void radixSortByKey(std::span<std::uint64_t> keys, std::span<std::uint32_t> values,
                    std::span<std::uint64_t> keyScratch, std::span<std::uint32_t> valueScratch) {
    assert(keys.size() == values.size());
    assert(keyScratch.size() >= keys.size() && valueScratch.size() >= values.size());
    if (keys.size() < 2) {
        return;
    }
    sortInPlace({keys.data(), values.data(), keyScratch.data(), valueScratch.data(), keys.size()},
                64);
}

} // namespace omicron
