// The GPU vertex of one point and the packing of a node's points into it (CPU side, no GL).
//
// 32 bytes per point: position (unit cube, float), colour (rgb + a logarithmic intensity byte),
// normal (GL_INT_2_10_10_10_REV, normalised; zero when unknown), splat radius (unit-cube
// units), the LAS bytes the colour modes and the class filter read (classification, return
// number, number of returns, flags; zero without a LAS column) and the GPS time as a float
// relative to a per-cloud base (a GPS time of 3e8 s keeps 32 s steps as a float; relative to
// a time within the flight it keeps milliseconds over hours). The splat attributes come from
// Hierarchy::nodeSplats: estimated from the node's own points for a build (a parent's fewer points
// get larger splats that cover its children's area), read from the file for a loaded hierarchy
// (with the node's splatScale applied).
#pragma once

#include "build/splat_estimator.hpp"
#include "points/attribute_statistics.hpp"

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
    std::uint8_t classification = 0;
    std::uint8_t returnNumber = 0;
    std::uint8_t numberOfReturns = 0;
    std::uint8_t lasFlags = 0; // las_flag bits (spare for the shaders today)
    float gpsTime = 0.0f;      // seconds after packNodeVertices's gpsTimeBase
};
static_assert(sizeof(PointVertex) == 32, "PointVertex is the GPU layout: keep it 32 bytes");

// Packs a unit normal into GL_INT_2_10_10_10_REV (x in the low 10 bits), signed normalised.
std::uint32_t packNormal2101010(float x, float y, float z);

// Reused buffers of packNodeVertices, one per thread, and the GPS times it packed.
struct NodePackScratch {
    NodeSplats splats;
    SplatScratch estimate;
    ValueRange gpsTimes;
};

// The GPS time a cloud's vertices are relative to: that of the first point of `node` (any
// time within the flight keeps float precision); 0 when the cloud has no GPS times.
double gpsTimeBaseOf(const Hierarchy& hierarchy, const OctreeNode& node);

// Replaces `out` with the vertices of the points `node` holds (in the node's order), GPS times
// relative to `gpsTimeBase` (their range added to scratch.gpsTimes). Any thread: nodes may be
// packed in parallel, each with its own scratch.
void packNodeVertices(const Hierarchy& hierarchy, const OctreeNode& node,
                      std::vector<PointVertex>& out, NodePackScratch& scratch,
                      double gpsTimeBase = 0.0);

// Packs nodes[i] into out[i] (out grows to nodes.size()), the nodes in parallel (oneTBB): the
// splat estimates make packing the costly part of an upload. Returns the range of the packed
// GPS times (relative to `gpsTimeBase`; empty without GPS times).
ValueRange packNodesVertices(const Hierarchy& hierarchy, std::span<const OctreeNode* const> nodes,
                             std::vector<std::vector<PointVertex>>& out, double gpsTimeBase = 0.0);

} // namespace omicron
