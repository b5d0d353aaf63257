#include "sort/bin_block_pool.hpp"

#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cassert>
#include <iterator>
#include <new>
#include <sys/mman.h>

namespace omicron {

BinBlockPool::BinBlockPool(std::size_t blockBytes, PageSize pages)
    : m_blockBytes(blockBytes), m_slabBytes(blockBytes * kBlocksPerSlab), m_pages(pages) {
    assert(blockBytes > 0 && blockBytes % kSmallPageBytes == 0);
}

BinBlockPool::~BinBlockPool() {
    for (const auto& [base, slab] : m_slabs) {
        munmap(base, m_slabBytes);
    }
}

void* BinBlockPool::allocate() {
    if (m_lastSlab == m_slabs.end() || m_lastSlab->second.carved == kBlocksPerSlab) {
        void* memory = mmap(nullptr, m_slabBytes, PROT_READ | PROT_WRITE,
                            MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        if (memory == MAP_FAILED) {
            throw std::bad_alloc();
        }
        if (m_pages == PageSize::Huge) {
            adviseHugePages(memory, m_slabBytes);
        }
        try {
            m_lastSlab = m_slabs.emplace(static_cast<std::byte*>(memory), Slab{}).first;
        } catch (...) { // leaves nothing mapped
            munmap(memory, m_slabBytes);
            throw;
        }
    }
    Slab& slab = m_lastSlab->second;
    return m_lastSlab->first + slab.carved++ * m_blockBytes;
}

void BinBlockPool::release(const std::vector<void*>& blocks) {
    for (const void* block : blocks) {
        // The slab that holds the block: the last one that starts at or before it.
        const auto after = m_slabs.upper_bound(static_cast<const std::byte*>(block));
        assert(after != m_slabs.begin());
        auto& [base, slab] = *std::prev(after);
        assert(static_cast<const std::byte*>(block) < base + m_slabBytes);
        assert(slab.released < slab.carved);
        if (++slab.released == slab.carved) {
            releasePages(base, slab.carved * m_blockBytes);
        }
    }
}

std::size_t BinBlockPool::releasedSlabCount() const {
    return static_cast<std::size_t>(
        std::count_if(m_slabs.begin(), m_slabs.end(), [](const auto& entry) {
            return entry.second.released == entry.second.carved;
        }));
}

} // namespace omicron
