// Which small pages of a set of parallel per-point arrays hold points someone still uses, so
// that giving a node's points back returns exactly the pages no resident node shares.
//
// A cloud paged in on demand (a large .omh, formats/omh_pager.hpp) keeps every attribute in an
// array indexed by point, reserved for all points and backed by memory only where written.
// Nodes are ranges of points that do not start on page boundaries, and a page of 4 KiB holds
// 341 positions but 2048 radii: releasing only the pages wholly inside an evicted node would
// leave the shared edge pages resident for ever (two per node and array: a full pass over a
// billion-point file would keep gigabytes). So each page counts the resident ranges that
// touch it, and is released (MADV_DONTNEED: it reads as zero afterwards) when that count
// falls to zero.
//
// Threads: acquire() and release() may run on different threads; a mutex orders them, so a
// page a loader has just acquired (and then writes outside the lock) is never released under
// it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

namespace omicron {

class ResidentPages {
public:
    // Adds an array of `count` elements of `elementBytes` at `base` (page-aligned, as
    // HugePageArray allocates). Call before the first acquire().
    void addArray(void* base, std::size_t elementBytes, std::size_t count);

    // Points [begin, end) are about to be written: their pages stay until released.
    void acquire(std::size_t begin, std::size_t end);
    // Points [begin, end) are no longer used: pages no acquired range touches are given back.
    // Returns how many pages were.
    std::size_t release(std::size_t begin, std::size_t end);

    std::size_t arrayCount() const { return m_arrays.size(); }

private:
    struct Array {
        std::uintptr_t base = 0;
        std::size_t elementBytes = 0;
        std::vector<std::uint32_t> users; // per page: acquired ranges touching it
    };
    // The pages of `array` that points [begin, end) touch: [first, last).
    static std::pair<std::size_t, std::size_t> pagesOf(const Array& array, std::size_t begin,
                                                       std::size_t end);

    std::mutex m_mutex;
    std::vector<Array> m_arrays;
};

} // namespace omicron
