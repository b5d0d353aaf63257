// Jobs run one at a time, in order, on a thread of its own, the thread kept from job to job.
// The `.omh` sweep hands each batch's write and the next stretch's read-ahead to such a
// thread; started per batch with std::async, a sweep of small batches spent much of its time
// creating threads (lion.ply saved in 28k batches of one root: 4.7 s, 2.9 s with this).
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace omicron {

class BackgroundJob {
public:
    // At most `depth` (>= 1) jobs queued or running: with 1, start() waits for the job before.
    explicit BackgroundJob(std::size_t depth = 1) : m_depth(std::max<std::size_t>(depth, 1)) {}
    BackgroundJob(const BackgroundJob&) = delete;
    BackgroundJob& operator=(const BackgroundJob&) = delete;
    // Waits for the jobs queued (what they threw is dropped: a destructor cannot rethrow, and
    // it only runs early when something else was thrown), then ends the thread.
    ~BackgroundJob();

    // Waits until fewer than `depth` jobs are queued or running, rethrows what a job threw
    // (the jobs queued behind a failed one are dropped, and `job` is not started), else
    // queues `job`. The thread is made at the first job.
    void start(std::function<void()> job);
    // Waits until every job queued has run; rethrows what one threw.
    void wait();

private:
    void run();
    // With the lock held: throws the stored error once.
    void rethrowError();

    std::size_t m_depth;
    std::mutex m_mutex;
    std::condition_variable m_changed;
    std::deque<std::function<void()>> m_jobs; // the front one runs; each leaves when done
    bool m_stopping = false;
    std::exception_ptr m_error;
    std::thread m_thread;
};

} // namespace omicron
