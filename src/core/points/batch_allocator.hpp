// The allocator of a PointBatch's columns. A reader fills one batch of 65,536 points and hands
// it to the sorter, which keeps two more: their big columns (positions, the LAS column) are
// fresh memory, touched once each, and on this project's test VM a first touch costs 3 ms per
// MiB on small pages against 0.08 ms on huge pages (2,200 page faults, about 25 ms, mostly on
// the reader's thread before the sorter had anything to do). A column of 256 KiB or more is
// therefore a whole number of 2 MiB pages advised as huge where they pay off
// (points/huge_page_buffer.hpp); smaller ones come from the heap as before.
#pragma once

#include "points/huge_page_buffer.hpp"

#include <cstddef>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <vector>

namespace omicron {

template <typename T> struct BatchAllocator {
    using value_type = T;
    static constexpr std::size_t kHugeFromBytes = std::size_t{256} << 10;
    static constexpr std::size_t kMaxBytes = std::numeric_limits<std::ptrdiff_t>::max() / 2;

    BatchAllocator() noexcept = default;
    template <typename U> BatchAllocator(const BatchAllocator<U>&) noexcept {}

    T* allocate(std::size_t count) {
        if (count > kMaxBytes / sizeof(T)) {
            throw std::bad_array_new_length();
        }
        if (!onHugePages(count)) {
            return std::allocator<T>{}.allocate(count);
        }
        return static_cast<T*>(allocateInHugePages(count * sizeof(T), PageSize::Huge));
    }

    void deallocate(T* memory, std::size_t count) noexcept {
        if (onHugePages(count)) {
            std::free(memory);
        } else {
            std::allocator<T>{}.deallocate(memory, count);
        }
    }

    friend bool operator==(const BatchAllocator&, const BatchAllocator&) noexcept { return true; }

private:
    // Where a column of `count` values lives: allocate and deallocate must agree.
    static bool onHugePages(std::size_t count) { return count * sizeof(T) >= kHugeFromBytes; }
};

// A column of a PointBatch.
template <typename T> using BatchColumn = std::vector<T, BatchAllocator<T>>;

} // namespace omicron
