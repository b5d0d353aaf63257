#include "io/overlapped_batch_consumer.hpp"

#include "points/morton_batch.hpp"

#include <utility>

namespace omicron {

OverlappedBatchConsumer::OverlappedBatchConsumer(Consumer consume, Helper whileWaiting)
    : m_consume(std::move(consume)), m_help(std::move(whileWaiting)),
      m_worker([this](std::stop_token stop) { work(stop); }) {}

OverlappedBatchConsumer::~OverlappedBatchConsumer() {
    stopWorker();
}

namespace {

bool sameShape(const PointBatch& a, const PointBatch& b) {
    return a.attributes == b.attributes && a.positions.size() == b.positions.size() &&
           a.normals.size() == b.normals.size() && a.colors.size() == b.colors.size() &&
           a.intensities.size() == b.intensities.size() && a.las.size() == b.las.size();
}

} // namespace

void OverlappedBatchConsumer::push(PointBatch& batch) {
    m_pointsPushed += batch.size();
    std::unique_lock lock(m_mutex);
    // Helps, a step at a time, rather than idle while the worker still holds a batch.
    while (m_help && m_hasWaiting && !m_failure) {
        lock.unlock();
        const bool helped = m_help(m_pointsPushed);
        lock.lock();
        if (!helped) {
            break;
        }
    }
    m_changed.wait(lock, [&] { return !m_hasWaiting || m_failure; });
    if (m_failure) {
        std::rethrow_exception(m_failure);
    }
    if (sameShape(m_waiting, batch)) {
        std::swap(m_waiting, batch); // copying cost the reader thread a tenth of its time
    } else {
        m_waiting = batch; // the first batches, the last; reuses the buffer's capacity
    }
    m_waitingCodes.resize(m_waiting.size());
    morton::encodeUnitBatch(m_waiting.positions, m_waitingCodes);
    m_hasWaiting = true;
    m_changed.notify_all();
}

void OverlappedBatchConsumer::finish() {
    {
        std::lock_guard lock(m_mutex);
        m_finished = true;
    }
    m_changed.notify_all();
    if (m_worker.joinable()) {
        m_worker.join(); // it consumes what is waiting, then returns
    }
    rethrowFailure();
}

void OverlappedBatchConsumer::work(std::stop_token stop) {
    PointBatch working;
    std::vector<morton::Code> workingCodes;
    while (true) {
        {
            std::unique_lock lock(m_mutex);
            m_changed.wait(lock, stop, [&] { return m_hasWaiting || m_finished; });
            if (!m_hasWaiting) {
                return; // finished, or stopped with nothing to do
            }
            if (stop.stop_requested()) {
                return; // the reader gave up: what waits is dropped
            }
            std::swap(working, m_waiting);
            std::swap(workingCodes, m_waitingCodes);
            m_hasWaiting = false;
        }
        m_changed.notify_all(); // the reader may copy the next batch meanwhile
        try {
            m_consume(working, workingCodes);
        } catch (...) {
            {
                std::lock_guard lock(m_mutex);
                m_failure = std::current_exception();
            }
            m_changed.notify_all();
            return;
        }
    }
}

void OverlappedBatchConsumer::stopWorker() {
    if (m_worker.joinable()) {
        m_worker.request_stop();
        m_changed.notify_all();
        m_worker.join();
    }
}

void OverlappedBatchConsumer::rethrowFailure() {
    std::lock_guard lock(m_mutex);
    if (m_failure) {
        std::rethrow_exception(m_failure);
    }
}

} // namespace omicron
