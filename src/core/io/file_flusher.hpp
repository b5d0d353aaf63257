// Has the disk persist a file while it is still being written (AtomicFileWriter's big files):
// each request wakes a thread of its own that calls fdatasync, so the fsync that ends the write
// is left with the last part. Persisting costs the disk time in proportion to what it has not
// yet persisted, and on a VM whose disk the host caches it is the host writing to its own disk:
// 0.18 s for 433 MB here even when every page had been written back ten seconds before. At the
// end of a save that time came after the last byte; spread over the save it mostly overlaps
// the writing (24.2 M-point `build --save` to a disk: final fsync 0.19 s -> 0.02-0.05 s).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace omicron {

class FileFlusher {
public:
    // Starts the thread for `fd`, which must stay open until stop(). Where no thread can be
    // had, requests do nothing: the final fsync persists it all, as without this.
    explicit FileFlusher(int fd);
    ~FileFlusher() { stop(); }
    FileFlusher(const FileFlusher&) = delete;
    FileFlusher& operator=(const FileFlusher&) = delete;

    // Asks for a flush; requests made while one runs are served by one more flush.
    void request();
    // Stops the thread after the flush under way, if any; returns the first errno a flush met
    // (0: none). A write-back error is reported once per descriptor, so the caller's own
    // fsync would not see it again.
    int stop();
    // Flushes done so far.
    std::uint64_t flushes() const;

private:
    void run();

    const int m_fd;
    mutable std::mutex m_mutex; // guards what follows but the thread
    std::condition_variable m_wake;
    bool m_requested = false;
    bool m_stopping = false;
    int m_error = 0;
    std::uint64_t m_flushes = 0;
    std::thread m_thread;
};

} // namespace omicron
