// One node of the octree built from a SortedCloud: 40 bytes, immutable once published.
//
// Points are never copied into nodes. Because the cloud is in Morton order, the input points
// under any node form one contiguous index range of the SortedCloud (the "covered" range). A
// leaf holds its whole covered range; a parent (and a leaf dropped to a sample by the paper's
// leaf collapse) holds the stratified sample of its children's held points (parent_sampler).
// That sample is stored as a list of indices only where it must be: when every child holds
// its whole covered range (as above the leaves), the children's held points are the parent's
// covered range and the sample is a formula of it (implicit); a paper-collapsed leaf's sample
// is the same formula of its own range.
#pragma once

#include "points/morton.hpp"

#include <cstdint>

namespace omicron {

// Pick i of the stratified sample of `count` out of `n` (i < count <= n < 2^32, see
// parent_sampler.hpp): floor((2i + 1) n / (2 count)). The product takes 65 bits at worst, so
// it is formed in 128 bits when n makes that possible.
inline std::uint64_t stratifiedPick(std::uint64_t i, std::uint64_t n, std::uint64_t count) {
    if (n < (std::uint64_t{1} << 31)) {
        return (2 * i + 1) * n / (2 * count); // below 2^63
    }
    __extension__ using Wide = unsigned __int128;
    return static_cast<std::uint64_t>(Wide{2 * i + 1} * n / (2 * count));
}

enum class NodeFlag : std::uint8_t {
    Leaf = 1u << 0,
    // A leaf one level above maxLevel that took the place of its only child (leaf collapse).
    Collapsed = 1u << 1,
};

struct OctreeNode {
    morton::Code code = 0;
    // The pointCount strictly ascending SortedCloud indices the node holds, inside its covered
    // range. Or nullptr: the node holds the stratified picks of its covered range, pick i being
    // coveredBegin + floor((2i + 1) coveredCount / (2 pointCount)): the whole range when
    // pointCount == coveredCount (a leaf), an implicit sample when it is less.
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
    // Holds every point it covers: [coveredBegin, coveredBegin + pointCount).
    bool holdsRange() const { return sampleIndices == nullptr && pointCount == coveredCount; }
    // Holds the stratified picks of its covered range, computed rather than stored.
    bool holdsImplicitSample() const {
        return sampleIndices == nullptr && pointCount != coveredCount;
    }

    // SortedCloud index of the i-th point this node holds (i < pointCount); ascending in i.
    std::uint32_t heldPoint(std::uint32_t i) const {
        if (sampleIndices != nullptr) {
            return sampleIndices[i];
        }
        if (pointCount == coveredCount) {
            return coveredBegin + i;
        }
        return coveredBegin +
               static_cast<std::uint32_t>(stratifiedPick(i, coveredCount, pointCount));
    }
};

static_assert(sizeof(OctreeNode) == 40, "OctreeNode layout: keep it small, it is per node");

} // namespace omicron
