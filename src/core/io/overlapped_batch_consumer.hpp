// Consumes a reader's batches on a thread of its own, one batch behind the reader.
//
// A reader parses on one thread and, through its callback, also hands every batch to the
// sorter (codes, bins, the copy into the arrival-order arrays) on that same thread: the read
// phase took the parse time plus the sorter's, about twice read_bench's parse time for LAS,
// with the second core mostly idle. Here the callback only copies the batch into a free buffer
// (two of them, reused) and computes its points' Morton codes, and returns, so the reader parses
// batch k + 1 while a worker thread consumes batch k. The codes are the reader thread's share
// because the sorter's share (bins, the copy into the arrival-order arrays and its page
// faults) is the longer one: the reader waited for it. Batches are consumed in order, each
// exactly once.
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

    explicit OverlappedBatchConsumer(Consumer consume);
    // Without finish() (the reader threw): waits for the batch being consumed, drops the one
    // waiting.
    ~OverlappedBatchConsumer();
    OverlappedBatchConsumer(const OverlappedBatchConsumer&) = delete;
    OverlappedBatchConsumer& operator=(const OverlappedBatchConsumer&) = delete;

    // Reader thread: copies `batch` for the worker and codes its points, waiting while the
    // worker still has the previous copy. Rethrows what the consumer threw (its later batches
    // are not consumed).
    void push(const PointBatch& batch);
    // Reader thread, after the last push: waits until every batch is consumed; rethrows what
    // the consumer threw.
    void finish();

private:
    void work(std::stop_token stop);
    void stopWorker();
    void rethrowFailure();

    Consumer m_consume;
    std::mutex m_mutex;
    std::condition_variable_any m_changed;
    PointBatch m_waiting;         // the next batch, copied by push (guarded by m_mutex)
    std::vector<morton::Code> m_waitingCodes; // its codes (guarded by m_mutex)
    bool m_hasWaiting = false;    // guarded by m_mutex
    bool m_finished = false;      // no more pushes (guarded by m_mutex)
    std::exception_ptr m_failure; // guarded by m_mutex
    std::jthread m_worker;        // last: started once the members above exist
};

} // namespace omicron
