// Storage for the point samples of parents: uint32 runs that never move.
//
// The builder's workers draft each worklist's samples into a buffer of their own, in
// parallel; the store adopts those buffers whole, so the one master thread copies nothing.
// Nodes keep a raw pointer into a buffer, so an adopted buffer is never resized or freed while
// the store lives (moving a vector into the store keeps its elements where they are).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

class SampleStore {
public:
    // One writer thread. Keeps `samples`; returns where its elements live now.
    const std::uint32_t* adopt(std::vector<std::uint32_t>&& samples) {
        m_bytesAllocated += samples.capacity() * sizeof(std::uint32_t);
        m_adopted.push_back(std::move(samples));
        return m_adopted.back().data();
    }

    std::size_t bytesAllocated() const { return m_bytesAllocated; }

private:
    std::vector<std::vector<std::uint32_t>> m_adopted;
    std::size_t m_bytesAllocated = 0;
};

} // namespace omicron
