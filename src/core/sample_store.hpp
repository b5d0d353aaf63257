// Storage for the point samples of parents: contiguous uint32 runs that never move.
//
// A bump allocator over large blocks, and buffers adopted whole from the builder's workers
// (their samples, drafted in parallel, are kept where they were written instead of being
// copied by the one master thread). Nodes keep a raw pointer to their run, so a block or
// buffer is never resized or freed while the store lives; the tail of a block that cannot fit
// the next run is left unused (at most one run's worth per block).
#pragma once

#include "huge_page_buffer.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

class SampleStore {
public:
    // 2 MiB blocks on huge pages: a build's samples fault in a few pages, not hundreds.
    static constexpr std::size_t kBlockIndices = kHugePageBytes / sizeof(std::uint32_t);

    // One writer thread. Returns space for `count` indices (count > 0).
    std::uint32_t* allocate(std::size_t count) {
        if (m_blocks.empty() || m_used + count > m_blockCapacity) {
            m_blockCapacity = count > kBlockIndices ? count : kBlockIndices;
            m_blocks.emplace_back(m_blockCapacity);
            m_bytesAllocated += m_blocks.back().bytesAllocated();
            m_used = 0;
        }
        std::uint32_t* run = m_blocks.back().data() + m_used;
        m_used += count;
        return run;
    }

    // One writer thread. Keeps `samples` (moving a vector keeps its elements in place).
    const std::uint32_t* adopt(std::vector<std::uint32_t>&& samples) {
        m_bytesAllocated += samples.capacity() * sizeof(std::uint32_t);
        m_adopted.push_back(std::move(samples));
        return m_adopted.back().data();
    }

    std::size_t bytesAllocated() const { return m_bytesAllocated; }

private:
    std::vector<HugePageArray<std::uint32_t>> m_blocks;
    std::vector<std::vector<std::uint32_t>> m_adopted;
    std::size_t m_blockCapacity = 0;
    std::size_t m_used = 0;
    std::size_t m_bytesAllocated = 0;
};

} // namespace omicron
