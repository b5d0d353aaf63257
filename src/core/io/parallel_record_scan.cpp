#include "io/parallel_record_scan.hpp"

#include "io/input_error.hpp"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <vector>

namespace omicron {

namespace {

std::uint64_t recordsPerBlock(const RecordArray& array, std::size_t blockBytes) {
    return std::max<std::uint64_t>(1, blockBytes / array.recordBytes);
}

[[noreturn]] void throwTruncated(const FileStream& stream, const RecordArray& array,
                                 std::uint64_t firstMissing, std::uint64_t fileEnd) {
    throw InputError(InputErrorKind::Truncated, stream.path(),
                     InputLocation::byte(array.start + firstMissing * array.recordBytes),
                     "expected record " + std::to_string(firstMissing) + " of " +
                         std::to_string(array.recordCount) + " (" +
                         std::to_string(array.recordBytes) + " bytes each from byte " +
                         std::to_string(array.start) + "), but the file ends at byte " +
                         std::to_string(fileEnd));
}

} // namespace

std::uint64_t recordBlockCount(const RecordArray& array, std::size_t blockBytes) {
    const std::uint64_t perBlock = recordsPerBlock(array, blockBytes);
    return (array.recordCount + perBlock - 1) / perBlock;
}

bool scanRecordsInParallel(const FileStream& stream, const RecordArray& array,
                           std::size_t blockBytes, std::size_t paddingBytes,
                           const ConcurrentBlockScan& scan, const InOrderBlockDone& done) {
    const std::uint64_t perBlock = recordsPerBlock(array, blockBytes);
    const std::uint64_t blocks = recordBlockCount(array, blockBytes);
    const auto bufferBytes = static_cast<std::size_t>(
        std::min(perBlock, array.recordCount) * array.recordBytes + paddingBytes);
    // Each thread takes the next block: blocks finish about in file order, so `done` (progress,
    // a preview sample) advances steadily. Splitting the range in halves would leave the second
    // half's blocks waiting until the first half was scanned.
    std::atomic<std::uint64_t> nextBlock{0};
    std::atomic<bool> stopped{false};
    std::mutex doneLock;
    std::vector<std::uint8_t> scanned(static_cast<std::size_t>(blocks), 0); // under doneLock
    std::uint64_t nextDone = 0;                                             // under doneLock
    // The earliest short read of any thread (a later block may fail first): the error names it.
    std::uint64_t firstMissing = array.recordCount; // under doneLock
    std::uint64_t fileEnd = 0;                      // under doneLock
    const int threads = std::max(1, tbb::this_task_arena::max_concurrency());
    tbb::parallel_for(0, threads, [&](int) {
        std::vector<std::uint8_t> buffer(bufferBytes);
        try {
            while (!stopped.load(std::memory_order_relaxed)) {
                const std::uint64_t block = nextBlock.fetch_add(1, std::memory_order_relaxed);
                if (block >= blocks) {
                    return;
                }
                const std::uint64_t first = block * perBlock;
                const auto count =
                    static_cast<std::size_t>(std::min(perBlock, array.recordCount - first));
                const std::size_t bytes = count * static_cast<std::size_t>(array.recordBytes);
                const std::size_t got =
                    stream.readAt(array.start + first * array.recordBytes, buffer.data(), bytes);
                if (got != bytes) {
                    std::lock_guard lock(doneLock);
                    const std::uint64_t missing = first + got / array.recordBytes;
                    if (missing < firstMissing) {
                        firstMissing = missing;
                        fileEnd = array.start + first * array.recordBytes + got;
                    }
                    stopped.store(true, std::memory_order_relaxed);
                    return;
                }
                scan(buffer.data(), count, first, block);
                std::lock_guard lock(doneLock);
                scanned[static_cast<std::size_t>(block)] = 1;
                while (nextDone < blocks && scanned[static_cast<std::size_t>(nextDone)] != 0 &&
                       !stopped.load(std::memory_order_relaxed)) {
                    const std::uint64_t end =
                        std::min(array.recordCount, (nextDone + 1) * perBlock);
                    if (!done(nextDone, array.start + end * array.recordBytes)) {
                        stopped.store(true, std::memory_order_relaxed);
                    }
                    ++nextDone;
                }
            }
        } catch (...) {
            stopped.store(true, std::memory_order_relaxed); // the other threads stop too
            throw;
        }
    });
    if (firstMissing < array.recordCount) {
        throwTruncated(stream, array, firstMissing, fileEnd);
    }
    return !stopped.load(std::memory_order_relaxed);
}

} // namespace omicron
