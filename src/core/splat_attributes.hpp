// Per-point splat attributes for the renderer: a radius everywhere, a normal where the input
// has none. Indexed like the SortedCloud, filled leaf by leaf by the hierarchy builder.
//
// Both come from the covariance of the points of a small cell of the leaf: the leaf is cut
// into fine cells of about 16 points each (on a surface); a cell with fewer than 8 points
// uses its smallest ancestor cell with enough, up to the leaf, and a sparse leaf uses its
// parent cell (its sibling group, which the builder always inserts whole). The smallest
// principal axis is the normal; the two largest give the patch area, and radius =
// sqrt(area / points), the spacing of the points on that patch. No neighbour search and no
// eigensolver: a build of 4.8M points spends ~90 ms here on one core. A parent node draws the
// same points with its OctreeNode::splatScale applied, which makes its fewer splats cover the
// area its children covered.
//
// Memory: 2 bytes per point for the radius (log2-encoded, 1/2048 octave steps over 2^-32..1)
// plus 4 bytes per point for an estimated normal (octahedral, 2 x 16-bit) only when the cloud
// has no normals of its own. Input normals are read from the SortedCloud as they are.
#pragma once

#include "sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <vector>

namespace omicron {

// Octahedral encoding of a unit vector in 2 x 16 bits (x in the low half).
std::uint32_t encodeOctahedral(const glm::vec3& unitNormal);
glm::vec3 decodeOctahedral(std::uint32_t encoded);
// Stored where no normal could be estimated (fewer than 3 points, or all on a line); decodes
// to (0, 0, 0): the renderer draws a screen-aligned splat there.
inline constexpr std::uint32_t kUnknownNormal = 0x80008000u;

std::uint16_t encodeRadius(float radius);
float decodeRadius(std::uint16_t encoded);

// Reused buffers of one thread's leaf estimates (the builder keeps one per worker).
struct SplatScratch {
    struct Moments {
        double count = 0.0;
        double sx = 0.0, sy = 0.0, sz = 0.0;
        double sxx = 0.0, sxy = 0.0, sxz = 0.0, syy = 0.0, syz = 0.0, szz = 0.0;
        void add(const glm::dvec3& p) { // inline: runs once per point of the cloud
            count += 1.0;
            sx += p.x;
            sy += p.y;
            sz += p.z;
            sxx += p.x * p.x;
            sxy += p.x * p.y;
            sxz += p.x * p.z;
            syy += p.y * p.y;
            syz += p.y * p.z;
            szz += p.z * p.z;
        }
        void add(const Moments& other);
    };
    std::vector<morton::Code> cellKeys;   // fine-cell codes, ascending
    std::vector<std::uint32_t> cellFirst; // first point of each cell (+ one past the last)
    std::vector<Moments> cellMoments;
};

class SplatAttributes {
public:
    // Allocates the per-point arrays for the cloud's full capacity.
    explicit SplatAttributes(const SortedCloud& cloud);

    SplatAttributes(const SplatAttributes&) = delete;
    SplatAttributes& operator=(const SplatAttributes&) = delete;

    bool estimatesNormals() const { return m_normals != nullptr; }

    // Valid for points of published leaves. Radius in unit-cube units, before splatScale.
    float radius(std::size_t point) const { return decodeRadius(m_radii[point]); }
    // The input's normal, or the estimate; (0, 0, 0) when unknown.
    glm::vec3 normal(std::size_t point) const;
    std::uint16_t encodedRadius(std::size_t point) const { return m_radii[point]; }
    // The estimated normal, octahedral-encoded; only when estimatesNormals().
    std::uint32_t encodedNormal(std::size_t point) const { return m_normals[point]; }

    std::size_t bytesPerPoint() const {
        return sizeof(std::uint16_t) + (estimatesNormals() ? sizeof(std::uint32_t) : 0);
    }
    std::size_t bytesResident() const { return bytesPerPoint() * m_capacity; }

    // Computes the attributes of the points [begin, end) of one leaf whose cell is at `level`;
    // [parentBegin, parentEnd) are all the points of its parent cell (its sibling group), which
    // a leaf with fewer than 8 points uses instead of its own. Deterministic (a fixed
    // summation order); leaves may be estimated concurrently.
    // Stores a point's attributes as a saved hierarchy holds them (the .omh reader): the
    // encoded radius and, when estimatesNormals(), the encoded normal (else it is ignored).
    void setEncoded(std::size_t point, std::uint16_t encodedRadius, std::uint32_t encodedNormal) {
        m_radii[point] = encodedRadius;
        if (m_normals) {
            m_normals[point] = encodedNormal;
        }
    }

    void estimateLeaf(std::size_t begin, std::size_t end, int level, std::size_t parentBegin,
                      std::size_t parentEnd, SplatScratch& scratch);

private:
    const SortedCloud& m_cloud;
    std::size_t m_capacity;
    // Left uninitialised: every point is written once, by the leaf that holds it, before the
    // leaf is published; the pages are first touched by the parallel estimates.
    std::unique_ptr<std::uint16_t[]> m_radii;
    std::unique_ptr<std::uint32_t[]> m_normals; // null when the cloud has normals
};

} // namespace omicron
