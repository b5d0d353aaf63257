// One job at a time on a thread of its own, the thread kept from job to job. The `.omh`
// sweep hands each batch's write and the next stretch's read-ahead to such a thread; started
// per batch with std::async, a sweep of small batches spent much of its time creating threads
// (lion.ply saved in 28k batches of one root: 4.7 s, 2.9 s with this).
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace omicron {

class BackgroundJob {
public:
    BackgroundJob() = default;
    BackgroundJob(const BackgroundJob&) = delete;
    BackgroundJob& operator=(const BackgroundJob&) = delete;
    // Waits for the job in flight (what it threw is dropped: a destructor cannot rethrow, and
    // it only runs early when something else was thrown), then ends the thread.
    ~BackgroundJob();

    // Waits for the job before (rethrowing what it threw), then starts `job`. The thread is
    // made at the first job.
    void start(std::function<void()> job);
    // Waits for the job in flight, if any; rethrows what it threw.
    void wait();

private:
    void run();

    std::mutex m_mutex;
    std::condition_variable m_changed;
    std::function<void()> m_job; // set from start() until the job is done
    bool m_stopping = false;
    std::exception_ptr m_error;
    std::thread m_thread;
};

} // namespace omicron
