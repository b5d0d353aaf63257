// Exports a finished hierarchy in the Potree 2.0 format, so the result opens in Potree and
// other tools that read PotreeConverter 2's output: a folder with
//   metadata.json   version "2.0", points, hierarchy {firstChunkSize, stepSize, depth},
//                   offset, scale, spacing, boundingBox, encoding "DEFAULT", attributes
//   hierarchy.bin   chunks of 22-byte node records (type u8: 0 normal, 1 leaf, 2 proxy;
//                   childMask u8; numPoints u32; byteOffset u64; byteSize u64), each chunk
//                   a breadth-first walk of `stepSize` levels below its root (children in
//                   Potree's child-index order); a node at a chunk's last level with children
//                   is a proxy whose offset/size locate its own chunk, which starts with it
//   octree.bin      each node's points, uncompressed ("DEFAULT"): position int32 x 3 (value =
//                   stored * scale + offset), then rgb uint16 x 3 (8-bit colour x 257) and
//                   intensity uint16 when the cloud has them
// Potree's child index is x << 2 | y << 1 | z (omicron's octant is z << 2 | y << 1 | x), and
// its bounding box is the hierarchy's cube in source units (plus the source offset), so each
// node's box is omicron's cell. Positions are quantised to 2^30 steps of the cube: the
// floor, so a point stays inside its node's box. Normals and splat attributes have no
// DEFAULT-encoding field in PotreeConverter's output and are not written.
#pragma once

#include "build/hierarchy.hpp"
#include "io/atomic_file_writer.hpp"

#include <cstdint>
#include <string>

namespace omicron {

struct PotreeExportOptions {
    std::string name = "omicron";
    int stepSize = 4; // hierarchy levels per chunk, as PotreeConverter 2 writes
};

struct PotreeExportSummary {
    std::uint64_t nodes = 0;
    std::uint64_t points = 0;
    std::uint64_t chunks = 0;
    std::uint64_t octreeBytes = 0;
};

// Quantisation steps per cube edge of the exported int32 positions.
inline constexpr std::uint32_t kPotreeStepsPerEdge = 1u << 30;

// Writes the three files into `folder` (created if missing; each file replaced atomically)
// from every published node of the complete `hierarchy`. Throws OutputError naming the file.
PotreeExportSummary exportPotree(const Hierarchy& hierarchy, const std::string& folder,
                                 const PotreeExportOptions& options = {});

} // namespace omicron
