#include "formats/background_job.hpp"

#include <utility>

namespace omicron {

BackgroundJob::~BackgroundJob() {
    if (!m_thread.joinable()) {
        return;
    }
    {
        std::unique_lock lock(m_mutex);
        m_changed.wait(lock, [this] { return !m_job; });
        m_stopping = true;
    }
    m_changed.notify_all();
    m_thread.join();
}

void BackgroundJob::start(std::function<void()> job) {
    wait();
    {
        const std::lock_guard lock(m_mutex);
        m_job = std::move(job);
    }
    if (!m_thread.joinable()) {
        m_thread = std::thread([this] { run(); });
    } else {
        m_changed.notify_all();
    }
}

void BackgroundJob::wait() {
    std::unique_lock lock(m_mutex);
    m_changed.wait(lock, [this] { return !m_job; });
    if (m_error) {
        std::rethrow_exception(std::exchange(m_error, nullptr));
    }
}

void BackgroundJob::run() {
    std::unique_lock lock(m_mutex);
    for (;;) {
        m_changed.wait(lock, [this] { return m_job || m_stopping; });
        if (!m_job) {
            return; // stopping, with nothing left to do
        }
        lock.unlock();
        std::exception_ptr error;
        try {
            m_job();
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        m_error = error;
        m_job = nullptr;
        m_changed.notify_all();
    }
}

} // namespace omicron
