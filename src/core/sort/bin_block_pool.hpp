// Page-aligned blocks for the sorter's bins, carved from slabs mapped a few at a time.
//
// The bins grow a block at a time on the thread that adds batches. From the heap, each block
// grew that thread's malloc arena with mprotect, which takes the address space's lock for
// writing, so it waited for every page populate the reader thread ran meanwhile (then
// MADV_POPULATE_WRITE, which holds that lock for reading): on autzen_south half the read phase's
// context switches were such waits, and the reader and the sorter ran one at a time. Here a
// slab of 16 MiB is mapped once every 1024 blocks of 16 KiB.
//
// A slab's memory goes back to the kernel (MADV_DONTNEED, the lock for reading) once all of
// its blocks are given back. Given back block by block, the 24.2 M points' bins took 2,300
// calls, each one waiting while the other core flushed its TLB: on a 2-core VM whose
// interrupts go through the hypervisor that cost 0.11 s of a 2.29 s `build --save` (10
// alternating runs each), for a peak 24 MB lower.
#pragma once

#include "points/huge_page_buffer.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

namespace omicron {

class BinBlockPool {
public:
    // Blocks of `blockBytes` each, a multiple of the small page size (asserted). Huge: the
    // slabs are advised huge pages where they pay off (points/huge_page_policy.hpp); a fresh
    // block then shares its 2 MiB page with blocks already written.
    explicit BinBlockPool(std::size_t blockBytes, PageSize pages = PageSize::Small);
    ~BinBlockPool(); // unmaps every slab: no block may be used after it
    BinBlockPool(const BinBlockPool&) = delete;
    BinBlockPool& operator=(const BinBlockPool&) = delete;

    // A fresh block, backed by memory only where written. One thread at a time; throws
    // std::bad_alloc when no slab can be mapped.
    void* allocate();
    // One thread at a time, after the last allocate(): the blocks' contents are no longer
    // needed (they are not handed out again). A slab's pages go back to the kernel, in one
    // call, when the last of its blocks is given back; the others keep their contents.
    void release(const std::vector<void*>& blocks);

    // Slabs mapped so far, and those whose pages went back (for tests).
    std::size_t slabCount() const { return m_slabs.size(); }
    std::size_t releasedSlabCount() const;

    static constexpr std::size_t kBlocksPerSlab = 1024;

private:
    struct Slab {
        std::size_t carved = 0;   // blocks handed out
        std::size_t released = 0; // of those, blocks given back
    };

    std::size_t m_blockBytes;
    std::size_t m_slabBytes;
    PageSize m_pages;
    using Slabs = std::map<std::byte*, Slab, std::less<>>; // by address: a block's slab is found
    Slabs m_slabs;
    Slabs::iterator m_lastSlab = m_slabs.end(); // the one allocate() carves
};

} // namespace omicron
