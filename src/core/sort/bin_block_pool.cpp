#include "sort/bin_block_pool.hpp"

#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cassert>
#include <new>
#include <sys/mman.h>

namespace omicron {

namespace {

constexpr std::size_t kBlocksPerSlab = 1024;

} // namespace

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

void BinBlockPool::release(std::vector<void*> blocks) const {
    std::sort(blocks.begin(), blocks.end());
    for (std::size_t i = 0; i < blocks.size();) {
        std::size_t end = i + 1;
        while (end < blocks.size() &&
               blocks[end] == static_cast<std::byte*>(blocks[end - 1]) + m_blockBytes) {
            ++end;
        }
        releasePages(blocks[i], (end - i) * m_blockBytes);
        i = end;
    }
}

} // namespace omicron
