#include "formats/background_job.hpp"

#include <utility>

namespace omicron {

BackgroundJob::~BackgroundJob() {
    if (!m_thread.joinable()) {
        return;
    }
    {
        std::unique_lock lock(m_mutex);
        m_changed.wait(lock, [this] { return m_jobs.empty(); });
        m_stopping = true;
    }
    m_changed.notify_all();
    m_thread.join();
}

void BackgroundJob::rethrowError() {
    if (m_error) {
        std::rethrow_exception(std::exchange(m_error, nullptr));
    }
}

void BackgroundJob::start(std::function<void()> job) {
    {
        std::unique_lock lock(m_mutex);
        m_changed.wait(lock, [this] { return m_jobs.size() < m_depth; });
        rethrowError();
        m_jobs.push_back(std::move(job));
    }
    if (!m_thread.joinable()) {
        m_thread = std::thread([this] { run(); });
    } else {
        m_changed.notify_all();
    }
}

void BackgroundJob::wait() {
    std::unique_lock lock(m_mutex);
    m_changed.wait(lock, [this] { return m_jobs.empty(); });
    rethrowError();
}

void BackgroundJob::run() {
    std::unique_lock lock(m_mutex);
    for (;;) {
        m_changed.wait(lock, [this] { return !m_jobs.empty() || m_stopping; });
        if (m_jobs.empty()) {
            return; // stopping, with nothing left to do
        }
        // The job stays at the front, counted as queued, until it is done.
        const std::function<void()>& job = m_jobs.front();
        lock.unlock();
        std::exception_ptr error;
        try {
            job();
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        if (error) {
            m_error = error;
            m_jobs.clear(); // what was queued behind it is not run
        } else {
            m_jobs.pop_front();
        }
        m_changed.notify_all();
    }
}

} // namespace omicron
