// Parallel, stable radix sort of 64-bit keys carrying 32-bit values (point indices).
//
// Most-significant-digit first: one stable counting pass distributes the keys by the top
// varying digit into buckets (histograms per fixed block of keys, all blocks in parallel),
// then every bucket is sorted the same way, independently and in parallel, until buckets are
// small enough for a stable insertion sort. Digits are taken only where keys actually differ,
// so clustered Morton codes (many equal high bits) cost no empty passes. Buckets and blocks
// are fixed by the data, not by the thread count, and every step is stable, so the output is
// the same for any number of threads (it is the unique stable order).
#pragma once

#include <cstdint>
#include <span>

namespace omicron {

// Sorts keys[i] ascending, moving values[i] along; equal keys keep their relative order.
// `keyScratch`/`valueScratch` have the same sizes as keys/values (at most 2^32 - 1 entries);
// the result always ends in keys/values.
void radixSortByKey(std::span<std::uint64_t> keys, std::span<std::uint32_t> values,
                    std::span<std::uint64_t> keyScratch, std::span<std::uint32_t> valueScratch);

} // namespace omicron
