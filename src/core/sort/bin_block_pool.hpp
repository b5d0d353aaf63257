// Page-aligned blocks for the sorter's bins, carved from large slabs mapped a few at a time.
//
// The bins grow a block at a time on the thread that adds batches. From the heap, each block
// grew that thread's malloc arena with mprotect, which takes the address space's lock for
// writing, so it waited for every page populate the reader thread ran meanwhile
// (MADV_POPULATE_WRITE holds that lock for reading): on autzen_south half the read phase's
// context switches were such waits, and the reader and the sorter ran one at a time. Here a
// slab of 16 MiB is mapped once every 1024 blocks of 16 KiB, and blocks given back are dropped
// with MADV_DONTNEED (the lock for reading), so their memory still goes back as soon as their
// bins are sorted and the sorted cloud reuses it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

class BinBlockPool {
public:
    // Blocks of `blockBytes` each, a multiple of the small page size (asserted).
    explicit BinBlockPool(std::size_t blockBytes);
    ~BinBlockPool(); // unmaps every slab: no block may be used after it
    BinBlockPool(const BinBlockPool&) = delete;
    BinBlockPool& operator=(const BinBlockPool&) = delete;

    // A fresh block, backed by memory only where written. One thread at a time; throws
    // std::bad_alloc when no slab can be mapped.
    void* allocate();
    // Any thread: the blocks' contents are no longer needed; their pages go back to the
    // kernel (the blocks are not handed out again). Blocks adjacent in memory go back in one
    // call: each call interrupts the other cores to flush their TLBs, and a call per block made
    // the sort of 24.2 M points 30 ms slower.
    void release(std::vector<void*> blocks) const;

private:
    std::size_t m_blockBytes;
    std::size_t m_slabBytes;
    std::vector<void*> m_slabs;
    std::size_t m_usedInLastSlab = 0;
};

} // namespace omicron
