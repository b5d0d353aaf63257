#include "points/page_recycler.hpp"

#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cassert>
#include <sys/mman.h>

#ifndef MREMAP_DONTUNMAP
#define MREMAP_DONTUNMAP 4 // Linux 5.7
#endif

namespace omicron {

PageRecycler::PageRecycler(std::span<std::byte> recipient, std::size_t pageBytes)
    : m_pageBytes(pageBytes), m_frontier(reinterpret_cast<std::uintptr_t>(recipient.data())),
      m_end(wholePages(recipient.data(), recipient.size(), pageBytes).last) {
    assert(m_frontier % m_pageBytes == 0);
}

std::uintptr_t PageRecycler::pageUp(std::uintptr_t address) const {
    return (address + m_pageBytes - 1) & ~(m_pageBytes - 1);
}

PageRecycler::~PageRecycler() {
    finish();
}

void PageRecycler::donate(const void* memory, std::size_t bytes) {
    const auto [first, last] = wholePages(memory, bytes, m_pageBytes);
    if (last <= first) {
        return;
    }
    if (!m_moving) {
        releasePages(reinterpret_cast<void*>(first), last - first);
        return;
    }
    if (!m_donations.empty() && m_donations.back().begin + m_donations.back().bytes == first) {
        m_donations.back().bytes += last - first; // one move, and one mapping, for both
    } else {
        m_donations.push_back({first, last - first});
    }
}

void PageRecycler::prepare(const void* end) {
    const std::uintptr_t target = std::min(pageUp(reinterpret_cast<std::uintptr_t>(end)), m_end);
    while (m_moving && m_frontier < target && !m_donations.empty()) {
        if (m_moves == kMaxMoves) {
            stopMoving();
            break;
        }
        Range& donation = m_donations.front();
        const std::size_t bytes = std::min<std::size_t>(donation.bytes, target - m_frontier);
        void* moved = mremap(reinterpret_cast<void*>(donation.begin), bytes, bytes,
                             MREMAP_MAYMOVE | MREMAP_FIXED | MREMAP_DONTUNMAP,
                             reinterpret_cast<void*>(m_frontier));
        if (moved == MAP_FAILED) { // the recipient's pages are as they were: fault them in
            stopMoving();
            break;
        }
        ++m_moves;
        m_pagesMoved += bytes / kSmallPageBytes;
        m_frontier += bytes;
        donation.begin += bytes;
        donation.bytes -= bytes;
        if (donation.bytes == 0) {
            m_donations.pop_front();
        }
    }
    m_frontier = std::max(m_frontier, target); // the rest is faulted in by the writes
}

void PageRecycler::finish() {
    for (const Range& donation : m_donations) {
        releasePages(reinterpret_cast<void*>(donation.begin), donation.bytes);
    }
    m_donations.clear();
}

void PageRecycler::stopMoving() {
    m_moving = false;
    finish();
}

} // namespace omicron
