// Parallel, stable radix sort of 64-bit keys carrying 32-bit values (point indices).
//
// Most-significant digit first, on the bits where keys actually differ (one OR pass finds
// them), so clustered Morton codes cost no passes over equal high bits:
// - A range of 2^16 keys or more is distributed by all threads in one stable counting
//   scatter by its top digit (up to 14 bits wide, aiming at buckets of ~2^11 keys):
//   histograms per fixed block of keys, a prefix in (digit, block) order, every block
//   scattering on its own. Buckets are then sorted in parallel, each by one thread in cache.
// - A cache-resident range is sorted in place by its two highest digits (up to 12 bits each)
//   least significant first: one pass counts both, two stable scatters go there and back.
//   For point-cloud codes that leaves few keys equal on all bits down to the low digit; such
//   groups are finished by insertion sort (up to 16 keys) or the same step on the bits below.
// Blocks and buckets are fixed by the data, not by the thread count, and every step is
// stable, so the output is the same for any number of threads (it is the unique stable order).
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
