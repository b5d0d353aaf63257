#include "sort/bin_block_pool.hpp"

#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cassert>
#include <functional>
#include <iterator>
#include <new>
#include <sys/mman.h>

namespace omicron {

BinBlockPool::BinBlockPool(std::size_t blockBytes)
    : m_blockBytes(blockBytes), m_slabBytes(blockBytes * kBlocksPerSlab),
      m_usedInLastSlab(m_slabBytes) {
    assert(blockBytes > 0 && blockBytes % kSmallPageBytes == 0);
}

BinBlockPool::~BinBlockPool() {
    for (void* slab : m_slabs) {
        munmap(slab, m_slabBytes);
    }
}

void* BinBlockPool::allocate() {
    if (m_usedInLastSlab == m_slabBytes) {
        m_slabs.reserve(m_slabs.size() + 1); // so that a failure below leaves nothing mapped
        void* slab = mmap(nullptr, m_slabBytes, PROT_READ | PROT_WRITE,
                          MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        if (slab == MAP_FAILED) {
            throw std::bad_alloc();
        }
        m_slabs.push_back(slab);
        m_usedInLastSlab = 0;
    }
    void* block = static_cast<std::byte*>(m_slabs.back()) + m_usedInLastSlab;
    m_usedInLastSlab += m_blockBytes;
    return block;
}

std::size_t BinBlockPool::slabOf(const void* block) {
    if (m_slabsByAddress.size() != m_slabs.size()) { // slabs were mapped since the last call
        m_slabsByAddress.resize(m_slabs.size());
        for (std::size_t s = 0; s < m_slabs.size(); ++s) {
            m_slabsByAddress[s] = s;
        }
        std::sort(
            m_slabsByAddress.begin(), m_slabsByAddress.end(),
            [this](std::size_t a, std::size_t b) { return std::less<>()(m_slabs[a], m_slabs[b]); });
    }
    // The last slab that starts at or before the block.
    const auto after = std::upper_bound(
        m_slabsByAddress.begin(), m_slabsByAddress.end(), block,
        [this](const void* at, std::size_t s) { return std::less<>()(at, m_slabs[s]); });
    assert(after != m_slabsByAddress.begin());
    const std::size_t slab = *std::prev(after);
    assert(static_cast<const std::byte*>(block) <
           static_cast<const std::byte*>(m_slabs[slab]) + m_slabBytes);
    return slab;
}

std::size_t BinBlockPool::carvedBlocks(std::size_t slab) const {
    return slab + 1 == m_slabs.size() ? m_usedInLastSlab / m_blockBytes : kBlocksPerSlab;
}

void BinBlockPool::release(const std::vector<void*>& blocks) {
    m_releasedBlocks.resize(m_slabs.size(), 0);
    for (const void* block : blocks) {
        const std::size_t slab = slabOf(block);
        const std::size_t carved = carvedBlocks(slab);
        assert(m_releasedBlocks[slab] < carved);
        if (++m_releasedBlocks[slab] == carved) {
            releasePages(m_slabs[slab], carved * m_blockBytes);
        }
    }
}

std::size_t BinBlockPool::releasedSlabCount() const {
    std::size_t released = 0;
    for (std::size_t slab = 0; slab < m_releasedBlocks.size(); ++slab) {
        const std::size_t carved = carvedBlocks(slab);
        released += m_releasedBlocks[slab] == carved ? 1 : 0;
    }
    return released;
}

} // namespace omicron
