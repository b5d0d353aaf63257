// Moves pages of memory that is done with into an array about to be written, instead of giving
// them back to the kernel and faulting fresh ones in.
//
// The in-memory sort gathers the arrival-order input into the sorted cloud chunk by chunk, and
// gives each block of input back once every chunk that reads it is sorted: the cloud grows as
// the input shrinks, by the same bytes per column. Given back (MADV_DONTNEED) and faulted in
// again, every 4 KiB page costs a fault, zeroing and the kernel's bookkeeping twice; where huge
// pages do not pay off (points/huge_page_policy.hpp) that is most of the sort's kernel time.
// mremap moves the page table entries instead (measured: 512 MiB in 5 ms, against 175 ms of
// faults), and the moved pages need no zeroing: every byte of them is written before it is
// published.
//
// On huge pages it moves whole 2 MiB pages (the kernel moves such a page's one table entry, and
// keeps it huge): given back, a huge page goes to the kernel's free lists, and where the host
// takes free memory back (free page reporting) it is often gone before the cloud faults its
// next page in, which then costs the host's fault and zeroing again (measured on a 2-core VM:
// 512 MiB given back and faulted in again 0.05 s at once, 0.6-0.9 s a second later).
//
// The donor's range stays mapped and reads as zero afterwards, as after MADV_DONTNEED
// (MREMAP_DONTUNMAP). Each move may add a memory mapping, so moves stop after kMaxMoves and
// pages are given back as before; a refused move (an old kernel) stops them too.
#pragma once

#include "points/huge_page_buffer.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>

namespace omicron {

class PageRecycler {
public:
    static constexpr std::size_t kMaxMoves = 8192;

    // `recipient`: an array aligned to `pageBytes` (4 KiB, or 2 MiB for arrays on huge pages)
    // owned by the caller, whose bytes are written front to back, each range announced by
    // prepare() first, and never touched before that.
    explicit PageRecycler(std::span<std::byte> recipient, std::size_t pageBytes = kSmallPageBytes);
    // Gives back the donations no prepare() used.
    ~PageRecycler();
    PageRecycler(const PageRecycler&) = delete;
    PageRecycler& operator=(const PageRecycler&) = delete;

    // The whole pages (of pageBytes) inside [memory, memory + bytes) will not be read again (they
    // read as zero afterwards): they back the recipient's next pages, or go back to the kernel.
    void donate(const void* memory, std::size_t bytes);
    // The recipient's bytes up to `end` are about to be written for the first time: the pages
    // not yet touched among them are backed by donated pages while there are any.
    void prepare(const void* end);
    // Gives back the donations no prepare() used (the recipient is complete).
    void finish();

    std::size_t pagesMoved() const { return m_pagesMoved; }
    std::size_t moves() const { return m_moves; }

private:
    struct Range {
        std::uintptr_t begin;
        std::size_t bytes;
    };
    void stopMoving();
    std::uintptr_t pageUp(std::uintptr_t address) const;

    std::size_t m_pageBytes;
    std::uintptr_t m_frontier; // the recipient's first page no one has touched
    std::uintptr_t m_end;
    std::deque<Range> m_donations;
    std::size_t m_moves = 0;
    std::size_t m_pagesMoved = 0;
    bool m_moving = true;
};

} // namespace omicron
