#include "formats/omh_top_levels.hpp"

#include <algorithm>
#include <cstring>

namespace omicron {

namespace {

std::uint64_t heldPoints(const Hierarchy& hierarchy, int levels) {
    std::uint64_t held = 0;
    for (int level = 0; level < levels; ++level) {
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            held += hierarchy.node(level, i).pointCount;
        }
    }
    return held;
}

} // namespace

std::uint64_t TopLevelPoints::bytesFor(const Hierarchy& hierarchy, int levels) {
    return heldPoints(hierarchy, levels) *
           (pointBytes(hierarchy.cloud().attributes()) + 2 * sizeof(std::uint32_t));
}

std::unique_ptr<TopLevelPoints> TopLevelPoints::plan(const Hierarchy& hierarchy, int levels) {
    const SortedCloud& source = hierarchy.cloud();
    const std::uint64_t held = heldPoints(hierarchy, levels);

    // Which points to gather: every level's held points (a level's are ascending, since its
    // nodes are in Morton order), merged without repeats.
    std::vector<std::uint32_t> points;
    points.reserve(static_cast<std::size_t>(held));
    for (int level = 0; level < levels; ++level) {
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                points.push_back(node.heldPoint(p));
            }
        }
    }
    std::sort(points.begin(), points.end());
    points.erase(std::unique(points.begin(), points.end()), points.end());

    std::unique_ptr<TopLevelPoints> top(new TopLevelPoints(hierarchy));
    top->m_held.resize(static_cast<std::size_t>(levels));
    top->m_firstHeld.resize(static_cast<std::size_t>(levels));
    for (int level = 0; level < levels; ++level) {
        std::vector<std::uint32_t>& renumbered = top->m_held[static_cast<std::size_t>(level)];
        std::vector<std::uint64_t>& first = top->m_firstHeld[static_cast<std::size_t>(level)];
        auto at = points.begin();
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            first.push_back(renumbered.size());
            for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                at = std::lower_bound(at, points.end(), node.heldPoint(p));
                renumbered.push_back(static_cast<std::uint32_t>(at - points.begin()));
            }
        }
    }

    top->m_cloud = std::make_shared<SortedCloud>(source.cube(), source.sourceOffset(),
                                                 source.attributes(), points.size());
    top->m_points = std::move(points);
    return top;
}

void TopLevelPoints::copyUpTo(std::uint64_t end) {
    const SortedCloud& source = m_hierarchy.cloud();
    SortedCloud& cloud = *m_cloud;
    const std::size_t lasBytes = source.attributes().lasBytes();
    const auto last = static_cast<std::size_t>(
        std::lower_bound(m_points.begin() + static_cast<std::ptrdiff_t>(m_copied), m_points.end(),
                         end) -
        m_points.begin());
    if (last == m_copied) {
        return;
    }
    const SortedCloud::StagedRange out = cloud.stage(last);
    for (std::size_t i = m_copied; i < last; ++i) {
        const std::uint32_t from = m_points[i];
        const std::size_t to = i - m_copied;
        out.positions[to] = source.position(from);
        if (!out.normals.empty()) {
            out.normals[to] = source.normals()[from];
        }
        if (!out.colors.empty()) {
            out.colors[to] = source.color(from);
        }
        if (!out.intensities.empty()) {
            out.intensities[to] = source.intensities()[from];
        }
        if (lasBytes != 0) {
            std::memcpy(out.las.data() + to * lasBytes, source.lasRecord(from), lasBytes);
        }
    }
    cloud.publish(last);
    m_copied = last;
}

void TopLevelPoints::finish() {
    copyUpTo(UINT64_MAX);
    m_cloud->markComplete();
    m_points = {};
}

OctreeNode TopLevelPoints::node(int level, std::size_t index) const {
    OctreeNode node = m_hierarchy.node(level, index);
    node.sampleIndices = m_held[static_cast<std::size_t>(level)].data() +
                         m_firstHeld[static_cast<std::size_t>(level)][index];
    return node;
}

} // namespace omicron
