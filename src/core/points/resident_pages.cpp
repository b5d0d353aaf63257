#include "points/resident_pages.hpp"

#include "points/huge_page_buffer.hpp"

#include <cassert>
#include <sys/mman.h>

namespace omicron {

void ResidentPages::addArray(void* base, std::size_t elementBytes, std::size_t count) {
    if (base == nullptr || count == 0) {
        return;
    }
    Array array;
    array.base = reinterpret_cast<std::uintptr_t>(base);
    assert(array.base % kSmallPageBytes == 0);
    array.elementBytes = elementBytes;
    array.users.assign((count * elementBytes + kSmallPageBytes - 1) / kSmallPageBytes, 0);
    std::lock_guard lock(m_mutex);
    m_arrays.push_back(std::move(array));
}

std::pair<std::size_t, std::size_t> ResidentPages::pagesOf(const Array& array, std::size_t begin,
                                                           std::size_t end) {
    if (begin >= end) {
        return {0, 0};
    }
    return {begin * array.elementBytes / kSmallPageBytes,
            (end * array.elementBytes + kSmallPageBytes - 1) / kSmallPageBytes};
}

void ResidentPages::acquire(std::size_t begin, std::size_t end) {
    std::lock_guard lock(m_mutex);
    for (Array& array : m_arrays) {
        const auto [first, last] = pagesOf(array, begin, end);
        for (std::size_t page = first; page < last; ++page) {
            ++array.users[page];
        }
    }
}

std::size_t ResidentPages::release(std::size_t begin, std::size_t end) {
    std::size_t released = 0;
    std::lock_guard lock(m_mutex);
    for (Array& array : m_arrays) {
        const auto pages = pagesOf(array, begin, end);
        const std::size_t first = pages.first, last = pages.second; // (a lambda captures them)
        // Consecutive free pages go back in one call.
        std::size_t runStart = last;
        const auto flush = [&](std::size_t runEnd) {
            if (runStart < runEnd) {
                madvise(reinterpret_cast<void*>(array.base + runStart * kSmallPageBytes),
                        (runEnd - runStart) * kSmallPageBytes, MADV_DONTNEED);
                released += runEnd - runStart;
            }
            runStart = last;
        };
        for (std::size_t page = first; page < last; ++page) {
            assert(array.users[page] > 0);
            if (--array.users[page] == 0) {
                runStart = std::min(runStart, page);
            } else {
                flush(page);
            }
        }
        flush(last);
    }
    return released;
}

} // namespace omicron
