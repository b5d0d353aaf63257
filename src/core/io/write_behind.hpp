// A region of a file written front to back once and not read back (a level of a .omh, a whole
// output file), whose bytes leave the page cache behind the writer: a multi-gigabyte output
// would otherwise fill the page cache and push out what the process reads meanwhile (the
// sorted points of a build beyond the memory budget are in a scratch file, read through the
// page cache while the .omh is written).
//
// Each window's write-back is started as soon as the window is complete, and a window is
// waited for and dropped from the cache only once the writer is kLagBytes past it: by then
// the device has had that long to write it, so the wait is rarely one. (Waiting for the window
// just behind, whose write-back had not even been started for a region's first window, held
// up a 24.2 M-point save to a disk for a device write of 64 MiB at each level's start.)
#pragma once

#include <cstdint>

namespace omicron {

// `File` is an AtomicFileWriter (or a test's recorder): startWriteBack(offset, count) and
// dropFromCache(offset, count).
class WriteBehind {
public:
    static constexpr std::uint64_t kWindowBytes = std::uint64_t{16} << 20;
    static constexpr std::uint64_t kLagBytes = std::uint64_t{64} << 20;

    explicit WriteBehind(std::uint64_t regionStart = 0)
        : m_started(regionStart), m_dropped(regionStart) {}

    // The region is written up to `end` (a file offset): starts the write-back of the windows
    // that completes, waits for and drops those now kLagBytes behind the last started.
    template <typename File> void advance(File& file, std::uint64_t end) {
        while (end - m_started >= kWindowBytes) {
            file.startWriteBack(m_started, kWindowBytes);
            m_started += kWindowBytes;
        }
        while (m_started - m_dropped > kLagBytes) {
            file.dropFromCache(m_dropped, kWindowBytes);
            m_dropped += kWindowBytes;
        }
    }

    // The region ends at `end`: starts the write-back of what is left (commit's fsync waits
    // for it); what is still cached stays (it leaves with the file's other clean pages).
    template <typename File> void finish(File& file, std::uint64_t end) {
        if (end > m_started) {
            file.startWriteBack(m_started, end - m_started);
            m_started = end;
        }
    }

private:
    std::uint64_t m_started; // write-back started up to here
    std::uint64_t m_dropped; // dropped from the page cache up to here
};

} // namespace omicron
