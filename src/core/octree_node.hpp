// One node of the octree built from a SortedCloud: 40 bytes, immutable once published.
//
// Points are never copied into nodes. Because the cloud is in Morton order, the input points
// under any node form one contiguous index range of the SortedCloud (the "covered" range). A
// leaf holds its whole covered range; a parent (and a leaf dropped to a sample by the paper's
// leaf collapse) holds a sorted list of SortedCloud indices chosen from its children.
#pragma once

#include "morton.hpp"

#include <cstdint>

namespace omicron {

enum class NodeFlag : std::uint8_t {
    Leaf = 1u << 0,
    // A leaf one level above maxLevel that took the place of its only child (leaf collapse).
    Collapsed = 1u << 1,
};

struct OctreeNode {
    morton::Code code = 0;
    // nullptr: the node holds SortedCloud indices [coveredBegin, coveredBegin + pointCount).
    // Otherwise pointCount strictly ascending SortedCloud indices inside the covered range.
    const std::uint32_t* sampleIndices = nullptr;
    std::uint32_t coveredBegin = 0; // first SortedCloud index of the subtree's input points
    std::uint32_t coveredCount = 0; // input points in the subtree
    std::uint32_t pointCount = 0;   // points this node holds (rendered at this level of detail)
    std::uint32_t firstChild = 0;   // index of the first child in the next level's node array
    // Splat radius multiplier for this node's points: a parent keeps fewer points than its
    // children, so each of its splats must cover the area of several child splats.
    float splatScale = 1.0f;
    std::uint8_t childCount = 0; // children are contiguous: [firstChild, firstChild + childCount)
    std::uint8_t flags = 0;

    int level() const { return morton::level(code); }
    bool has(NodeFlag flag) const { return (flags & static_cast<std::uint8_t>(flag)) != 0; }
    bool isLeaf() const { return has(NodeFlag::Leaf); }
    bool holdsRange() const { return sampleIndices == nullptr; }

    // SortedCloud index of the i-th point this node holds (i < pointCount); ascending in i.
    std::uint32_t heldPoint(std::uint32_t i) const {
        return sampleIndices == nullptr ? coveredBegin + i : sampleIndices[i];
    }
};

static_assert(sizeof(OctreeNode) == 40, "OctreeNode layout: keep it small, it is per node");

} // namespace omicron
