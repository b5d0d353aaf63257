// A point cloud in Morton order that grows by its sorted prefix.
//
// Points keep their positions (unit cube), not their codes: a level-21 code is
// morton::encodeUnit(position), bit for bit what the sorter sorted by, so storing it would
// cost 8 bytes a point for nothing (a third of the cloud). Scans that only ask "same cell?"
// test positions against a UnitCellBox, which needs no bit interleaving.
//
// The arrays are allocated once, for the cloud's full capacity, and never move. A producer
// (the incremental sorter, or the .oms reader) fills them front to back and publishes the end
// of the finished prefix with a release store; any thread that loads sortedEnd() (acquire) may
// read [0, sortedEnd()) without locks: that part never changes again. This is the hand-off
// between the sorting stage and the hierarchy builder (pipelines 1 and 2 of the paper).
#pragma once

#include "cube_transform.hpp"
#include "huge_page_buffer.hpp"
#include "morton.hpp"
#include "point_batch.hpp"

#include <atomic>
#include <cassert>
#include <cstddef>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

namespace omicron {

// The order the points of a cloud are stored in.
enum class CloudOrder {
    Morton, // non-decreasing level-21 code: what the sorter and the .oms reader produce and the
            // builder needs (publish() asserts it at range boundaries)
    // The held points of a stored hierarchy's nodes, concatenated in node (breadth-first)
    // order, as the .omh reader loads them: a parent's sample repeats points of its leaves,
    // and codes restart at every level. Only a loaded Hierarchy indexes such a cloud.
    NodeOrder,
};

class SortedCloud {
public:
    SortedCloud(const CubeTransform& cube, const glm::dvec3& sourceOffset, AttributeSet attributes,
                std::size_t capacity, CloudOrder order = CloudOrder::Morton)
        : m_cube(cube), m_sourceOffset(sourceOffset), m_attributes(attributes), m_order(order),
          m_positions(capacity), m_normals(attributes.has(Attribute::Normal) ? capacity : 0),
          m_colors(attributes.has(Attribute::Color) ? capacity : 0),
          m_intensities(attributes.has(Attribute::Intensity) ? capacity : 0) {}

    SortedCloud(const SortedCloud&) = delete;
    SortedCloud& operator=(const SortedCloud&) = delete;

    const CubeTransform& cube() const { return m_cube; }
    const glm::dvec3& sourceOffset() const { return m_sourceOffset; }
    AttributeSet attributes() const { return m_attributes; }
    CloudOrder order() const { return m_order; }
    std::size_t capacity() const { return m_positions.size(); }

    // End of the finished prefix; everything before it is immutable.
    std::size_t sortedEnd() const { return m_sortedEnd.load(std::memory_order_acquire); }
    // True once the producer declared the cloud complete (sortedEnd() is then the point count).
    bool complete() const { return m_complete.load(std::memory_order_acquire); }

    // Read access; index only below a sortedEnd() value this thread has loaded.
    // The level-21 code of point `i` (computed from its position).
    morton::Code code(std::size_t i) const {
        const glm::vec3& p = m_positions[i];
        return morton::encodeUnit(p.x, p.y, p.z);
    }
    std::span<const glm::vec3> positions() const { return m_positions; }
    std::span<const glm::vec3> normals() const { return m_normals; }
    std::span<const glm::u8vec3> colors() const { return m_colors; }
    std::span<const std::uint16_t> intensities() const { return m_intensities; }

    // Producer side: write beyond sortedEnd(), then publish.
    std::span<glm::vec3> mutablePositions() { return m_positions; }
    std::span<glm::vec3> mutableNormals() { return m_normals; }
    std::span<glm::u8vec3> mutableColors() { return m_colors; }
    std::span<std::uint16_t> mutableIntensities() { return m_intensities; }

    void publish(std::size_t newSortedEnd) {
        const std::size_t previous = m_sortedEnd.load(std::memory_order_relaxed);
        assert(newSortedEnd >= previous && newSortedEnd <= capacity());
        assert(m_order != CloudOrder::Morton || previous == 0 || newSortedEnd == previous ||
               code(previous - 1) <= code(previous));
        (void)previous;
        m_sortedEnd.store(newSortedEnd, std::memory_order_release);
    }
    void markComplete() { m_complete.store(true, std::memory_order_release); }

    // Copies [begin, end) into a batch (e.g. for a writer or a test).
    void copyRange(std::size_t begin, std::size_t end, PointBatch& out) const;

private:
    CubeTransform m_cube;
    glm::dvec3 m_sourceOffset;
    AttributeSet m_attributes;
    CloudOrder m_order;
    // On huge pages, uninitialised: the producer writes [0, capacity) before publishing.
    HugePageArray<glm::vec3> m_positions;
    HugePageArray<glm::vec3> m_normals;
    HugePageArray<glm::u8vec3> m_colors;
    HugePageArray<std::uint16_t> m_intensities;
    std::atomic<std::size_t> m_sortedEnd{0};
    std::atomic<bool> m_complete{false};
};

} // namespace omicron
