// Storage for the point samples of parents: uint32 runs that never move.
//
// The builder's workers draft each worklist's samples into a buffer of their own, in
// parallel; the store adopts those buffers whole, so the one master thread copies nothing.
// Nodes keep a raw pointer into a buffer, so an adopted buffer is never resized or freed while
// the store lives (moving a vector into the store keeps its elements where they are).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace omicron {

// An allocator whose resize() leaves new elements uninitialised: a sample buffer is written
// right after it grows, so zeroing it first would only double the writes.
template <typename T> struct UninitializedAllocator : std::allocator<T> {
    template <typename U> struct rebind {
        using other = UninitializedAllocator<U>;
    };
    UninitializedAllocator() = default;
    template <typename U> UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
    template <typename U, typename... Args> void construct(U* p, Args&&... args) {
        if constexpr (sizeof...(Args) == 0) {
            ::new (static_cast<void*>(p)) U; // default-initialised: left as it is
        } else {
            ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
        }
    }
};

using SampleBuffer = std::vector<std::uint32_t, UninitializedAllocator<std::uint32_t>>;

class SampleStore {
public:
    // One writer thread. Keeps `samples`; returns where its elements live now.
    const std::uint32_t* adopt(SampleBuffer&& samples) {
        m_bytesAllocated += samples.capacity() * sizeof(std::uint32_t);
        m_adopted.push_back(std::move(samples));
        return m_adopted.back().data();
    }

    std::size_t bytesAllocated() const { return m_bytesAllocated; }

private:
    std::vector<SampleBuffer> m_adopted;
    std::size_t m_bytesAllocated = 0;
};

} // namespace omicron
