// Splat attributes (a radius everywhere, a normal where the input has none) of the points one
// node holds, estimated from those points when a renderer or a writer asks for them.
//
// The estimate is the covariance of the node's points in small cells: the node's cell is cut
// into fine cells of about 32 of its points each (on a surface); a fine cell with fewer than 8
// points uses its smallest ancestor cell with enough, up to the node's cell, and a node with
// fewer than 8 points borrows the shape of a larger region (see SparseSplatRegion). The
// smallest principal axis is the normal; the two largest give the patch area, and radius =
// sqrt(area / points), the spacing of the node's points on that patch. A parent holds a sample
// of its children's points, so its radius comes out larger by about sqrt(1 / ratio): its fewer
// splats cover the area its children covered. No neighbour search and no eigensolver.
//
// Nothing is estimated while the hierarchy is built: a build costs what cutting the sorted
// stream into nodes costs, and only the nodes a renderer draws (or a file save writes) pay for
// their attributes. The result depends only on the node and the cloud (a fixed summation
// order), so every thread, every frame and every save computes the same bytes.
#pragma once

#include "build/octree_node.hpp"
#include "points/sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

// The attributes of a node's held points, in the node's order.
struct NodeSplats {
    std::vector<std::uint16_t> radii;   // encodeRadius, unit-cube units, before splatScale
    std::vector<std::uint32_t> normals; // encodeOctahedral; empty when the cloud has normals
};

// The region a node with fewer than 8 points takes its shape from: a range of the cloud that
// contains the node's points, and how many of the node's points lie in it, for the density.
// A leaf uses its sibling group (all at the leaf's density); a parent its covered range
// (holding only its sample). A region no larger than the node is not used, and a node with at
// least kMinPointsPerSplatEstimate points never uses it (an empty region will do).
struct SparseSplatRegion {
    std::uint32_t begin = 0;
    std::uint32_t count = 0;
    std::uint64_t nodePoints = 0;
};

// A cell (or a whole node) with fewer points borrows a larger neighbourhood's shape.
inline constexpr std::uint32_t kMinPointsPerSplatEstimate = 8;

// Reused buffers of one thread's estimates.
struct SplatScratch {
    struct Moments {
        double count = 0.0;
        double sx = 0.0, sy = 0.0, sz = 0.0;
        double sxx = 0.0, sxy = 0.0, sxz = 0.0, syy = 0.0, syz = 0.0, szz = 0.0;
        void add(double x, double y, double z) { // inline: runs once per point drawn
            count += 1.0;
            sx += x;
            sy += y;
            sz += z;
            sxx += x * x;
            sxy += x * y;
            sxz += x * z;
            syy += y * y;
            syz += y * z;
            szz += z * z;
        }
        void add(const Moments& other) { // inline: runs for every cell a sparse cell widens to
            count += other.count;
            sx += other.sx;
            sy += other.sy;
            sz += other.sz;
            sxx += other.sxx;
            sxy += other.sxy;
            sxz += other.sxz;
            syy += other.syy;
            syz += other.syz;
            szz += other.szz;
        }
    };
    std::vector<morton::Code> cellKeys;   // fine-cell codes, ascending
    std::vector<std::uint32_t> cellFirst; // first held point of each cell (+ one past the last)
    std::vector<Moments> cellMoments;
};

// Fills `out` with the attributes of the points `node` holds (indices below the cloud's
// published prefix); normals only when `estimateNormals` (the cloud has none of its own).
void estimateNodeSplats(const SortedCloud& cloud, const OctreeNode& node,
                        const SparseSplatRegion& sparseRegion, bool estimateNormals,
                        NodeSplats& out, SplatScratch& scratch);

} // namespace omicron
