// The merging side of a sort larger than memory: the sorted runs (RunSpiller) read back
// through one buffer each and merged into a single stream in Morton order. Ties go to the
// earlier run, and runs hold the input in order, so the stream is the stable Morton order of
// the whole input: point for point what the in-memory sorter emits. While a run's buffer is
// merged, its next buffer's bytes are read ahead into the page cache on a helper thread, so a
// refill rarely waits for the disk.
#pragma once

#include "points/morton.hpp"
#include "points/point_batch.hpp"
#include "points/point_records.hpp"
#include "sort/run_spiller.hpp"

#include <cstdint>
#include <future>
#include <vector>

namespace omicron {

class RunMerger {
public:
    // `bufferBytes` is shared by the runs' read buffers (at least one record each). A run that
    // leaves a column out (RunSpiller) gives each of its points `leftOut`'s value (its
    // lasRecord must outlive the merger).
    RunMerger(const std::vector<SortedRun>& runs, std::size_t bufferBytes,
              const LeftOutColumns& leftOut = {});

    // Appends the next (at most `maxPoints`) points of the stream to `out` (whose attributes
    // must be the cloud's the runs were spilled from) and returns how many; 0 once the stream
    // is over.
    std::size_t next(PointBatch& out, std::size_t maxPoints);

    std::uint64_t pointsLeft() const { return m_pointsLeft; }

private:
    struct Cursor {
        const ScratchFile* file = nullptr;
        PointRecordLayout layout; // of the run's records
        std::size_t recordsPerBuffer = 1;
        std::uint64_t points = 0;     // in the run
        std::uint64_t nextToLoad = 0; // first point not in the buffer yet
        std::vector<std::uint8_t> records;
        std::vector<morton::Code> codes; // of the buffered records
        std::size_t at = 0;              // next buffered record
        std::size_t buffered = 0;
    };

    bool refill(Cursor& cursor);                           // false once the run is exhausted
    bool lessThan(std::uint32_t a, std::uint32_t b) const; // heap order: (code, run)
    void siftDown(std::size_t slot);

    LeftOutColumns m_leftOut;
    std::vector<Cursor> m_cursors;
    std::vector<std::uint32_t> m_heap; // cursor indices, smallest (code, run) on top
    std::uint64_t m_pointsLeft = 0;
    // The read-ahead of the last refilled run's next buffer. Last: destroyed first, waiting.
    std::future<void> m_readAhead;
};

} // namespace omicron
