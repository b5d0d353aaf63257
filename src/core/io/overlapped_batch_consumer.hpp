// Consumes a reader's batches on a thread of its own, one batch behind the reader.
//
// A reader parses on one thread and, through its callback, also hands every batch to the
// sorter (codes, bins, the copy into the arrival-order arrays) on that same thread: the read
// phase took the parse time plus the sorter's, about twice read_bench's parse time for LAS,
// with the second core mostly idle. Here the callback only swaps the batch with a free buffer
// (two of them, reused) and computes its points' Morton codes, and returns, so the reader parses
// batch k + 1 while a worker thread consumes batch k. The codes are the reader thread's share
// because the sorter's share (bins, the copy into the arrival-order arrays and its page
// faults) is the longer one: the reader waited for it. Where it still waits, it may help
// instead (the sorter's page faults ahead, IncrementalMortonSorter::populateAhead). Batches
// are consumed in order, each exactly once.
#pragma once

#include "points/morton.hpp"
#include "points/point_batch.hpp"

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <span>
#include <thread>

namespace omicron {

class OverlappedBatchConsumer {
public:
    // A batch and the level-21 codes of its points (morton::encodeUnit), one per point.
    using Consumer = std::function<void(const PointBatch&, std::span<const morton::Code>)>;

    // Work the reader thread may do while the worker still holds the previous batch, a small
    // step per call, given the points read so far (the batch being pushed included); returns
    // false when it has nothing to do (the reader then waits).
    using Helper = std::function<bool(std::size_t pointsRead)>;

    explicit OverlappedBatchConsumer(Consumer consume, Helper whileWaiting = {});
    // Without finish() (the reader threw): waits for the batch being consumed, drops the one
    // waiting.
    ~OverlappedBatchConsumer();
    OverlappedBatchConsumer(const OverlappedBatchConsumer&) = delete;
    OverlappedBatchConsumer& operator=(const OverlappedBatchConsumer&) = delete;

    // Reader thread: hands `batch` to the worker and codes its points, waiting while the
    // worker still holds the previous one. The batch is taken by swapping it with the buffer
    // the worker is done with when both have the same attributes and column sizes (every
    // full batch after the first two: `batch` then holds that buffer's stale points), and
    // copied otherwise. Rethrows what the consumer threw (its later batches are not consumed).
    void push(PointBatch& batch);
    // Reader thread, after the last push: waits until every batch is consumed; rethrows what
    // the consumer threw.
    void finish();

private:
    void work(std::stop_token stop);
    void stopWorker();
    void rethrowFailure();

    Consumer m_consume;
    Helper m_help;
    std::size_t m_pointsPushed = 0; // reader thread only
    std::mutex m_mutex;
    std::condition_variable_any m_changed;
    PointBatch m_waiting;                     // the next batch, taken by push (guarded by m_mutex)
    std::vector<morton::Code> m_waitingCodes; // its codes (guarded by m_mutex)
    bool m_hasWaiting = false;    // guarded by m_mutex
    bool m_finished = false;      // no more pushes (guarded by m_mutex)
    std::exception_ptr m_failure; // guarded by m_mutex
    std::jthread m_worker;        // last: started once the members above exist
};

} // namespace omicron
