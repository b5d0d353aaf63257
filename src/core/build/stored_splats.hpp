// The splat attributes a saved hierarchy carries, per point of its node-order cloud.
//
// A built hierarchy estimates the attributes of a node when it is drawn or saved
// (splat_estimator.hpp); a hierarchy loaded from a .omh file has them already, one record per
// held point, so the loader stores them here and the renderer reads them instead of estimating.
//
// Memory: 2 bytes per point for the radius plus 4 bytes per point for an estimated normal only
// when the cloud has no normals of its own.
#pragma once

#include "points/sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>

namespace omicron {

class StoredSplats {
public:
    // Allocates the per-point arrays for the cloud's full capacity.
    explicit StoredSplats(const SortedCloud& cloud)
        : m_capacity(cloud.capacity()),
          m_radii(std::make_unique_for_overwrite<std::uint16_t[]>(m_capacity)),
          m_normals(cloud.attributes().has(Attribute::Normal)
                        ? nullptr
                        : std::make_unique_for_overwrite<std::uint32_t[]>(m_capacity)) {}

    StoredSplats(const StoredSplats&) = delete;
    StoredSplats& operator=(const StoredSplats&) = delete;

    bool estimatesNormals() const { return m_normals != nullptr; }
    // Valid for points of published levels.
    std::uint16_t encodedRadius(std::size_t point) const { return m_radii[point]; }
    // Only when estimatesNormals().
    std::uint32_t encodedNormal(std::size_t point) const { return m_normals[point]; }

    // The loader's side: a point's attributes as the file holds them (the normal is ignored
    // when the cloud has normals of its own).
    void setEncoded(std::size_t point, std::uint16_t encodedRadius, std::uint32_t encodedNormal) {
        m_radii[point] = encodedRadius;
        if (m_normals) {
            m_normals[point] = encodedNormal;
        }
    }

    std::size_t bytesResident() const {
        return m_capacity * (sizeof(std::uint16_t) + (m_normals ? sizeof(std::uint32_t) : 0));
    }

private:
    std::size_t m_capacity;
    // Left uninitialised: the loader writes every point of a level before publishing it.
    std::unique_ptr<std::uint16_t[]> m_radii;
    std::unique_ptr<std::uint32_t[]> m_normals; // null when the cloud has normals
};

} // namespace omicron
