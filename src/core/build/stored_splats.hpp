// The splat attributes a saved hierarchy carries, per point of its node-order cloud.
//
// A built hierarchy estimates the attributes of a node when it is drawn or saved
// (splat_estimator.hpp); a hierarchy loaded from a .omh file has some already, so the loader
// stores them here and the renderer reads them instead of estimating: before version 3 every
// held point's, from version 3 only those of nodes too sparse for an estimate of their own.
//
// Memory: 2 bytes per point for the radius plus 4 bytes per point for an estimated normal only
// when the cloud has no normals of its own.
#pragma once

#include "points/sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace omicron {

class StoredSplats {
public:
    // Allocates the per-point arrays for the cloud's full capacity, in small pages for a cloud
    // paged in on demand (so a node's attributes are released with its points) and where only
    // the few points of sparse nodes are stored (`sparseNodesOnly`, a version 3 .omh: the
    // pages nothing writes stay unmapped, where a huge page would map 2 MiB around each).
    StoredSplats(const SortedCloud& cloud, bool sparseNodesOnly)
        : m_capacity(cloud.capacity()), m_sparseNodesOnly(sparseNodesOnly),
          m_radii(m_capacity, pageSize(cloud, sparseNodesOnly)),
          m_normals(cloud.attributes().has(Attribute::Normal) ? 0 : m_capacity,
                    pageSize(cloud, sparseNodesOnly)) {}

    StoredSplats(const StoredSplats&) = delete;
    StoredSplats& operator=(const StoredSplats&) = delete;

    bool estimatesNormals() const { return m_normals.size() != 0; }
    // Only the points of nodes too sparse for an estimate of their own have attributes here.
    bool sparseNodesOnly() const { return m_sparseNodesOnly; }
    // Valid for points of published levels.
    std::uint16_t encodedRadius(std::size_t point) const { return m_radii[point]; }
    // Only when estimatesNormals().
    std::uint32_t encodedNormal(std::size_t point) const { return m_normals[point]; }

    // The loader's side: a point's attributes as the file holds them (the normal is ignored
    // when the cloud has normals of its own).
    void setEncoded(std::size_t point, std::uint16_t encodedRadius, std::uint32_t encodedNormal) {
        m_radii[point] = encodedRadius;
        if (estimatesNormals()) {
            m_normals[point] = encodedNormal;
        }
    }
    // The arrays themselves, for a pager that gives their pages back (resident_pages.hpp).
    std::span<std::uint16_t> mutableRadii() { return m_radii; }
    std::span<std::uint32_t> mutableNormals() { return m_normals; }

    std::size_t bytesResident() const {
        return m_capacity * (sizeof(std::uint16_t) + (estimatesNormals() ? sizeof(std::uint32_t) : 0));
    }

private:
    static PageSize pageSize(const SortedCloud& cloud, bool sparseNodesOnly) {
        return cloud.pagedOnDemand() || sparseNodesOnly ? PageSize::Small : PageSize::Huge;
    }

    std::size_t m_capacity;
    bool m_sparseNodesOnly;
    // Left uninitialised: the loader writes every point of a level before publishing it.
    HugePageArray<std::uint16_t> m_radii;
    HugePageArray<std::uint32_t> m_normals; // empty when the cloud has normals
};

} // namespace omicron
