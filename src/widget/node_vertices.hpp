// The GPU vertex of one point and the packing of a node's points into it (CPU side, no GL).
//
// 24 bytes per point: position (unit cube, float), colour (rgb + a logarithmic intensity byte),
// normal (GL_INT_2_10_10_10_REV, normalised; zero when unknown) and splat radius (unit-cube
// units). The splat attributes come from Hierarchy::nodeSplats: estimated from the node's own
// points for a build (a parent's fewer points get larger splats that cover its children's
// area), read from the file for a loaded hierarchy (with the node's splatScale applied).
#pragma once

#include "build/splat_estimator.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace omicron {

class Hierarchy;
struct OctreeNode;

struct PointVertex {
    float x = 0.0f, y = 0.0f, z = 0.0f;
    std::uint8_t r = 0, g = 0, b = 0, intensity = 0;
    std::uint32_t normal = 0;
    float radius = 0.0f;
};
static_assert(sizeof(PointVertex) == 24, "PointVertex is the GPU layout: keep it 24 bytes");

// Packs a unit normal into GL_INT_2_10_10_10_REV (x in the low 10 bits), signed normalised.
std::uint32_t packNormal2101010(float x, float y, float z);

// Reused buffers of packNodeVertices, one per thread.
struct NodePackScratch {
    NodeSplats splats;
    SplatScratch estimate;
};

// Replaces `out` with the vertices of the points `node` holds (in the node's order). Any
// thread: nodes may be packed in parallel, each with its own scratch.
void packNodeVertices(const Hierarchy& hierarchy, const OctreeNode& node,
                      std::vector<PointVertex>& out, NodePackScratch& scratch);

// Packs nodes[i] into out[i] (out grows to nodes.size()), the nodes in parallel (oneTBB): the
// splat estimates make packing the costly part of an upload.
void packNodesVertices(const Hierarchy& hierarchy, std::span<const OctreeNode* const> nodes,
                       std::vector<std::vector<PointVertex>>& out);

} // namespace omicron
