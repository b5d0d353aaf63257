#include "formats/potree_additive.hpp"

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace omicron {

namespace {

// True when points `a` and `b` of `cloud` are one point: the same index in a Morton-order
// cloud, equal records in a node-order one (where a parent's copy has its own index).
class SamePoint {
public:
    explicit SamePoint(const SortedCloud& cloud)
        : m_cloud(cloud), m_byIndex(cloud.order() == CloudOrder::Morton),
          m_normals(cloud.attributes().has(Attribute::Normal)),
          m_colors(cloud.attributes().has(Attribute::Color)),
          m_intensities(cloud.attributes().has(Attribute::Intensity)),
          m_lasBytes(cloud.attributes().lasBytes()) {}

    bool operator()(std::uint32_t a, std::uint32_t b) const {
        if (a == b) {
            return true;
        }
        if (m_byIndex) {
            return false;
        }
        const glm::vec3 pa = m_cloud.position(a), pb = m_cloud.position(b);
        // Bits, not values: a copy is bit for bit what it copies (and -0 is not 0 here).
        if (std::memcmp(&pa, &pb, sizeof(pa)) != 0) {
            return false;
        }
        if (m_normals &&
            std::memcmp(&m_cloud.normals()[a], &m_cloud.normals()[b], sizeof(glm::vec3)) != 0) {
            return false;
        }
        if (m_colors && m_cloud.color(a) != m_cloud.color(b)) {
            return false;
        }
        if (m_intensities && m_cloud.intensities()[a] != m_cloud.intensities()[b]) {
            return false;
        }
        return m_lasBytes == 0 ||
               std::memcmp(m_cloud.lasRecord(a), m_cloud.lasRecord(b), m_lasBytes) == 0;
    }

private:
    const SortedCloud& m_cloud;
    bool m_byIndex, m_normals, m_colors, m_intensities;
    std::size_t m_lasBytes;
};

std::string describe(int level, std::size_t index, const OctreeNode& node) {
    char code[32];
    std::snprintf(code, sizeof(code), "%llx", static_cast<unsigned long long>(node.code));
    return "node " + std::to_string(index) + " of level " + std::to_string(level) + " (code 0x" +
           code + ")";
}

} // namespace

void visitAdditiveNodes(const Hierarchy& hierarchy, const AdditiveNodeVisitor& visit) {
    const SamePoint same(hierarchy.cloud());
    std::vector<std::uint32_t> points;
    const OctreeNode& root = hierarchy.node(0, 0);
    points.resize(root.pointCount);
    for (std::uint32_t i = 0; i < root.pointCount; ++i) {
        points[i] = root.heldPoint(i);
    }
    visit(0, 0, points);

    // Per sibling group: which of the children's held points (concatenated) the parent holds.
    std::vector<std::uint8_t> inParent;
    for (int level = 0; level < hierarchy.maxLevel(); ++level) {
        const std::size_t parents = hierarchy.nodeCount(level);
        std::size_t nextChild = 0;
        for (std::size_t p = 0; p < parents; ++p) {
            const OctreeNode& parent = hierarchy.node(level, p);
            if (parent.childCount == 0) {
                continue;
            }
            if (parent.firstChild != nextChild) {
                throw NotNestedError(describe(level, p, parent) +
                                     ": its children do not follow its predecessors' children");
            }
            nextChild += parent.childCount;
            std::size_t groupPoints = 0;
            for (std::uint32_t c = 0; c < parent.childCount; ++c) {
                groupPoints += hierarchy.node(level + 1, parent.firstChild + c).pointCount;
            }
            inParent.assign(groupPoints, 0);
            // The merge: each point of the parent, in order, is the next equal point of the
            // children's list (the parent's list is a subsequence of it).
            std::uint32_t child = 0, held = 0;
            std::size_t flat = 0;
            for (std::uint32_t i = 0; i < parent.pointCount; ++i) {
                const std::uint32_t wanted = parent.heldPoint(i);
                for (;;) {
                    if (child == parent.childCount) {
                        throw NotNestedError(describe(level, p, parent) + ": its point " +
                                             std::to_string(i) +
                                             " is held by none of its children");
                    }
                    const OctreeNode& node = hierarchy.node(level + 1, parent.firstChild + child);
                    if (held == node.pointCount) {
                        ++child;
                        held = 0;
                        continue;
                    }
                    const bool match = same(wanted, node.heldPoint(held));
                    ++held;
                    ++flat;
                    if (match) {
                        inParent[flat - 1] = 1;
                        break;
                    }
                }
            }
            flat = 0;
            for (std::uint32_t c = 0; c < parent.childCount; ++c) {
                const std::size_t index = parent.firstChild + c;
                const OctreeNode& node = hierarchy.node(level + 1, index);
                points.clear();
                for (std::uint32_t i = 0; i < node.pointCount; ++i, ++flat) {
                    if (inParent[flat] == 0) {
                        points.push_back(node.heldPoint(i));
                    }
                }
                visit(level + 1, index, points);
            }
        }
        if (nextChild != hierarchy.nodeCount(level + 1)) {
            throw NotNestedError("level " + std::to_string(level + 1) + " has " +
                                 std::to_string(hierarchy.nodeCount(level + 1)) +
                                 " nodes, its parents announce " + std::to_string(nextChild));
        }
    }
}

} // namespace omicron
