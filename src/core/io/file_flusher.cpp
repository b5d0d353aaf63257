#include "io/file_flusher.hpp"

#include <cerrno>
#include <system_error>
#include <unistd.h>

namespace omicron {

FileFlusher::FileFlusher(int fd) : m_fd(fd) {
    try {
        m_thread = std::thread([this] { run(); });
    } catch (const std::system_error&) {
        m_stopping = true; // no thread to spare: request() does nothing
    }
}

void FileFlusher::request() {
    {
        const std::lock_guard lock(m_mutex);
        m_requested = true;
    }
    m_wake.notify_one();
}

void FileFlusher::run() {
    std::unique_lock lock(m_mutex);
    while (true) {
        m_wake.wait(lock, [this] { return m_requested || m_stopping; });
        if (m_stopping) {
            return;
        }
        m_requested = false;
        lock.unlock();
        // The data only: the file's size and blocks were set when it was extended, and its
        // times are the final fsync's.
        const int error = ::fdatasync(m_fd) == 0 ? 0 : errno;
        lock.lock();
        ++m_flushes;
        if (error != 0 && m_error == 0) {
            m_error = error;
        }
    }
}

int FileFlusher::stop() {
    {
        const std::lock_guard lock(m_mutex);
        m_stopping = true;
    }
    m_wake.notify_one();
    if (m_thread.joinable()) {
        m_thread.join();
    }
    return m_error;
}

std::uint64_t FileFlusher::flushes() const {
    const std::lock_guard lock(m_mutex);
    return m_flushes;
}

} // namespace omicron
