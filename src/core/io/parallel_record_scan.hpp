// Scans an array of fixed-size records in blocks read at once on several threads (pread), for
// a pass whose work per record is small next to the kernel's copy of the bytes: a bounds
// pre-pass. RecordBlockReader reads the next block as one task while the caller parses this
// one, so such a pass ran on one core (the caller finished its block first and read the next
// itself): autzen_south.ply's pre-pass took 25 ms with the second core idle.
#pragma once

#include "io/file_stream.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>

namespace omicron {

struct RecordArray {
    std::uint64_t start = 0;       // byte offset of the first record
    std::uint64_t recordBytes = 1; // > 0
    std::uint64_t recordCount = 0;
};

// Called on any scanning thread, for blocks in any order: records [firstIndex, firstIndex +
// count) at `records` (the call's to change in place), followed by `paddingBytes` readable bytes.
using ConcurrentBlockScan = std::function<void(std::uint8_t* records, std::size_t count,
                                               std::uint64_t firstIndex, std::uint64_t blockIndex)>;
// Called once per block after its scan, one call at a time and in file order (block 0, 1, ...),
// with the byte just past the block; false stops the scan (no later block is passed on).
using InOrderBlockDone = std::function<bool(std::uint64_t blockIndex, std::uint64_t endByte)>;

// Blocks hold blockBytes / recordBytes whole records (at least one); blockIndex counts them.
std::uint64_t recordBlockCount(const RecordArray& array, std::size_t blockBytes);

// Scans every block of `array` on the calling thread and oneTBB's workers. Returns false when
// `done` stopped it. Throws Truncated (naming the first missing record) when the file ends
// before the array does, and rethrows read errors and the callbacks' exceptions.
bool scanRecordsInParallel(const FileStream& stream, const RecordArray& array,
                           std::size_t blockBytes, std::size_t paddingBytes,
                           const ConcurrentBlockScan& scan, const InOrderBlockDone& done);

} // namespace omicron
