// Read-only views of a sorted cloud's positions, one per point store (see SortedCloud), so that
// scans over positions are written once and compiled for each store.
#pragma once

#include "points/packed_points.hpp"

#include <concepts>
#include <cstddef>
#include <glm/vec3.hpp>

namespace omicron {

// Positions read straight from the exact store's array.
struct ExactPositions {
    const glm::vec3* data;
    const glm::vec3& operator[](std::size_t i) const { return data[i]; }
    // Asks for the cache lines of points [first, first + count).
    void prefetch(std::size_t first, std::size_t count) const {
        const char* begin = reinterpret_cast<const char*>(data + first);
        const char* end = reinterpret_cast<const char*>(data + first + count);
        for (const char* line = begin; line < end; line += 64) {
            __builtin_prefetch(line);
        }
    }
};

// Positions decoded from the packed store (each access decodes one point).
struct PackedPositions {
    const PackedPointStore* store;
    glm::vec3 operator[](std::size_t i) const { return store->position(i); }
    void prefetch(std::size_t first, std::size_t count) const { store->prefetch(first, count); }
};

template <typename T>
concept PositionView = requires(const T& view, std::size_t i) {
    { view[i] } -> std::convertible_to<glm::vec3>;
    view.prefetch(i, i);
};

} // namespace omicron
