// hierarchy.bin of a Potree 2.0 export: chunks of 22-byte node records (type u8: 0 normal,
// 1 leaf, 2 proxy; childMask u8; numPoints u32; byteOffset u64; byteSize u64, little-endian).
// A chunk is the breadth-first walk of `stepSize` levels below its root, children in Potree's
// child-index order (x << 2 | y << 1 | z; omicron's octant is z << 2 | y << 1 | x), which is
// the order Potree's parseHierarchy creates them in. A node `stepSize` levels below its chunk's
// root that has children is a proxy: its offset and size locate its own chunk, whose first
// record is the node itself. The root's chunk comes first; its size is metadata.json's
// hierarchy.firstChunkSize.
//
// A subtree whose nodes store no point at all (every point went up to an ancestor in the
// additive export) is left out, as PotreeConverter drops children it emptied: such a node would
// only make a loader fetch zero bytes. A node that stores none but has descendants that do
// stays, with numPoints 0.
#pragma once

#include "build/hierarchy.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

// Where one node's points went in octree.bin.
struct PotreeNodePoints {
    std::uint32_t count = 0;
    std::uint64_t byteOffset = 0;
};

struct PotreeHierarchyFile {
    std::vector<std::uint8_t> bytes; // the whole hierarchy.bin
    std::uint64_t firstChunkSize = 0;
    std::uint64_t chunks = 0;
    std::uint64_t nodes = 0; // nodes written (proxies counted once, with their chunk)
    int depth = 0;           // deepest level written
};

// The hierarchy.bin of `hierarchy`'s nodes (complete), with the points of node i of level l
// at points[l][i] and `recordBytes` bytes a point. stepSize >= 1.
PotreeHierarchyFile layoutPotreeHierarchy(const Hierarchy& hierarchy,
                                          const std::vector<std::vector<PotreeNodePoints>>& points,
                                          std::size_t recordBytes, int stepSize);

} // namespace omicron
