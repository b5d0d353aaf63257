#include "build/splat_estimator.hpp"

#include "build/cell_sums.hpp"
#include "build/parent_sampler.hpp"
#include "build/splat_encoding.hpp"
#include "points/unit_cell_box.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>
#include <optional>

namespace omicron {

namespace {

// Fine cells hold about this many points on a surface (cells on a surface grow 4x per level):
// enough for a stable estimate, few enough to stay local; the per-cell work is most of the cost
// (measured: 32 estimates the leaves of autzen_south 1.5x faster than 16).
constexpr double kPointsPerFineCell = 32.0;
// A cell with fewer points borrows the moments of its smallest ancestor cell with enough.
constexpr double kMinPointsPerEstimate = kMinPointsPerSplatEstimate;
// Below this second invariant (relative to trace^2) a neighbourhood is a line or a point.
constexpr double kPlanarity = 1e-4;
// A sparse node's region is sampled with at most this many evenly spaced points: its shape
// needs no more, and a parent's covered range may hold millions.
constexpr std::uint32_t kRegionSamples = 256;

// Fine-cell depth below the node: about kPointsPerFineCell points per cell on a surface.
int fineDepth(std::size_t points, int level) {
    const double ratio = static_cast<double>(points) / kPointsPerFineCell;
    const int depth = ratio <= 1.0 ? 0 : static_cast<int>(std::lround(0.5 * std::log2(ratio)));
    return std::clamp(depth, 0, morton::kMaxLevel - level);
}

struct CellEstimate {
    float radius = 0.0f;
    std::uint32_t normal = kUnknownNormal;
};

// Radius and normal from the covariance C of a cell's points, for `density` points of the node
// on that patch, without an eigensolver (this runs for every fine cell drawn): the second
// invariant I2 = l1 l2 + l1 l3 + l2 l3 is l1 l2 on a surface (l3 ~ 0), and a uniform patch with
// sides a, b has l1 = a^2/12 and l2 = b^2/12, so its area is 12 sqrt(I2). The normal is the
// dominant eigenvector of the adjugate of C (eigenvalues l2 l3, l1 l3, l1 l2: largest for the
// smallest axis of C), from its largest column and two power steps.
CellEstimate estimateCell(const SplatScratch::Moments& m, double density, double cellEdge,
                          double maxRadius, bool wantNormal) {
    // Centring needs double (the sums are relative to the node's corner, the cell is small);
    // the centred covariance is well conditioned, so the rest runs in float, whose square
    // roots and divisions cost less on this per-cell path.
    const double inverse = 1.0 / m.count;
    const double mx = m.sx * inverse, my = m.sy * inverse, mz = m.sz * inverse;
    const auto cxx = static_cast<float>(std::max(0.0, m.sxx * inverse - mx * mx));
    const auto cyy = static_cast<float>(std::max(0.0, m.syy * inverse - my * my));
    const auto czz = static_cast<float>(std::max(0.0, m.szz * inverse - mz * mz));
    const auto cxy = static_cast<float>(m.sxy * inverse - mx * my);
    const auto cxz = static_cast<float>(m.sxz * inverse - mx * mz);
    const auto cyz = static_cast<float>(m.syz * inverse - my * mz);
    const float trace = cxx + cyy + czz;
    // Adjugate (cofactor matrix) of the symmetric C.
    const float a00 = cyy * czz - cyz * cyz, a11 = cxx * czz - cxz * cxz,
                a22 = cxx * cyy - cxy * cxy;
    const float a01 = cxz * cyz - cxy * czz, a02 = cxy * cyz - cxz * cyy,
                a12 = cxy * cxz - cxx * cyz;
    const float secondInvariant = std::max(0.0f, a00 + a11 + a22);
    const bool planar = m.count >= 3.0 && trace > 0.0f &&
                        secondInvariant > static_cast<float>(kPlanarity) * trace * trace;

    CellEstimate estimate;
    float radius;
    if (planar) {
        radius = std::sqrt(12.0f * std::sqrt(secondInvariant) / static_cast<float>(density));
    } else if (trace > 0.0f) {
        radius = std::sqrt(12.0f * trace) / static_cast<float>(density); // a line: its spacing
    } else {
        radius = static_cast<float>(0.5 * cellEdge); // coincident points: nothing to measure
    }
    constexpr float kMinRadius = 1.0f / float(std::uint64_t{1} << 22); // half a level-21 cell
    estimate.radius = std::clamp(radius, kMinRadius, static_cast<float>(maxRadius));
    if (!wantNormal || !planar) {
        return estimate;
    }
    glm::vec3 v = a00 >= a11 && a00 >= a22 ? glm::vec3(a00, a01, a02)
                  : a11 >= a22             ? glm::vec3(a01, a11, a12)
                                           : glm::vec3(a02, a12, a22);
    // Only the direction matters, to the power steps and to the octahedral code (which
    // divides by the L1 norm itself): each step rescales by the largest component (one
    // division, to keep the floats far from underflow), and no step takes a square root.
    // Unit lengths at each step and at the end (three roots, nine divisions) made every
    // node's estimate of autzen_south 7 % slower.
    for (int step = 0; step < 2; ++step) {
        const float largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
        if (!(largest > 0.0f) || !std::isfinite(largest)) {
            return estimate;
        }
        v *= 1.0f / largest;
        v = glm::vec3(a00 * v.x + a01 * v.y + a02 * v.z, a01 * v.x + a11 * v.y + a12 * v.z,
                      a02 * v.x + a12 * v.y + a22 * v.z);
    }
    const float norm1 = std::abs(v.x) + std::abs(v.y) + std::abs(v.z);
    if (!(norm1 > 0.0f) || !std::isfinite(norm1)) {
        return estimate;
    }
    // PCA gives no side; up (+z) is the common convention for scans (terrain, buildings).
    if (v.z < 0.0f) {
        v = -v;
    }
    estimate.normal = encodeOctahedral(v);
    return estimate;
}

// Splits the held points into the fine cells of `fineLevel` and sums their moments relative to
// `origin`; a cell's key is its code at fineLevel. `pointAt(i)` is the cloud index of the i-th
// held point.
template <typename Positions, typename PointAt>
void sumCellsOf(const Positions& positions, std::uint32_t count, int fineLevel,
                const glm::dvec3& origin, PointAt pointAt, SplatScratch& scratch) {
    const int shift = 3 * (morton::kMaxLevel - fineLevel);
    const auto cellCode = [&](const glm::vec3& p) {
        return morton::encodeUnit(p.x, p.y, p.z) >> shift;
    };
    scratch.cellKeys.clear();
    scratch.cellFirst.clear();
    scratch.cellMoments.clear();
    // Sums stay in registers while a cell lasts (appending through the vector each point
    // would force them through memory). Points are tested against the cell's box (no bit
    // interleaving); a cell's code is computed once, when it starts.
    CellSums current(origin);
    const glm::vec3 firstPoint = positions[pointAt(0)];
    current.start(firstPoint);
    UnitCellBox currentBox = UnitCellBox::of(firstPoint, fineLevel);
    morton::Code currentCode = cellCode(firstPoint);
    std::uint32_t currentFirst = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
        const glm::vec3 p = positions[pointAt(i)];
        if (!currentBox.contains(p)) {
            scratch.cellKeys.push_back(currentCode);
            scratch.cellFirst.push_back(currentFirst);
            scratch.cellMoments.push_back(current.moments());
            current.start(p);
            currentBox = UnitCellBox::of(p, fineLevel);
            currentCode = cellCode(p);
            currentFirst = i;
        }
        current.add(p);
    }
    scratch.cellKeys.push_back(currentCode);
    scratch.cellFirst.push_back(currentFirst);
    scratch.cellMoments.push_back(current.moments());
    scratch.cellFirst.push_back(count);
}

template <typename PointAt>
void sumCells(const SortedCloud& cloud, std::uint32_t count, int fineLevel,
              const glm::dvec3& origin, PointAt pointAt, SplatScratch& scratch) {
    cloud.visitPositions([&](const auto& positions) {
        sumCellsOf(positions, count, fineLevel, origin, pointAt, scratch);
    });
}

// Moments of at most kRegionSamples evenly spaced points of the region (the parents'
// stratified picks).
SplatScratch::Moments regionMoments(const SortedCloud& cloud, const SparseSplatRegion& region,
                                    const glm::dvec3& origin) {
    std::array<std::uint32_t, kRegionSamples> picks;
    const std::span<std::uint32_t> samples(picks.data(), std::min(region.count, kRegionSamples));
    sampleRange(region.begin, region.count, samples);
    SplatScratch::Moments moments;
    for (const std::uint32_t point : samples) {
        const glm::vec3 p = cloud.position(point);
        moments.add(p.x - origin.x, p.y - origin.y, p.z - origin.z);
    }
    return moments;
}

} // namespace

void estimateNodeSplats(const SortedCloud& cloud, const OctreeNode& node,
                        const SparseSplatRegion& sparseRegion, bool estimateNormals,
                        NodeSplats& out, SplatScratch& scratch) {
    const std::uint32_t count = node.pointCount;
    out.radii.resize(count);
    out.normals.resize(estimateNormals ? count : 0);
    if (count == 0) {
        return;
    }
    const int level = node.level();
    const int depth = fineDepth(count, level);
    const int fineLevel = level + depth;
    const double nodeEdge = std::ldexp(1.0, -level);
    const double fineEdge = std::ldexp(1.0, -fineLevel);
    const morton::Cell nodeCell = morton::decode(node.code);
    // Moments relative to the node's corner keep the double sums well conditioned.
    const glm::dvec3 origin = glm::dvec3(nodeCell.x, nodeCell.y, nodeCell.z) * nodeEdge;
    if (node.holdsRange()) { // most points: the leaves'
        const std::uint32_t begin = node.coveredBegin;
        sumCells(
            cloud, count, fineLevel, origin, [begin](std::uint32_t i) { return begin + i; },
            scratch);
    } else {
        sumCells(
            cloud, count, fineLevel, origin, [&node](std::uint32_t i) { return node.heldPoint(i); },
            scratch);
    }

    // A node too sparse for an estimate of its own borrows its region's shape.
    const bool useRegion = sparseRegion.count > count && sparseRegion.nodePoints > 0;
    bool regionSummed = false;
    SplatScratch::Moments region;
    const std::size_t cells = scratch.cellKeys.size();
    // The widened sum of the last sparse cell, one per level up, and the estimate from it once
    // asked for: its neighbours in Morton order usually widen to the same ancestors, and get
    // the same sum and estimate. One cache for all levels made a cell that needed two levels up
    // evict the level its next neighbour needed first (autzen_south tiled x5: 1.13 M sums over
    // 13.8 M cells for 1.75 M sparse cells, 60 % of its fine cells).
    struct Widened {
        morton::Code ancestor = ~morton::Code{0}; // no cell's ancestor
        SplatScratch::Moments sum;
        std::optional<CellEstimate> estimate;
    };
    std::array<Widened, morton::kMaxLevel + 1> widened;
    for (std::size_t c = 0; c < cells; ++c) {
        const SplatScratch::Moments* moments = &scratch.cellMoments[c];
        double density = moments->count;
        int up = 0;
        Widened* level = nullptr; // where the moments come from when widened
        while (moments->count < kMinPointsPerEstimate && up < depth) {
            ++up;
            const morton::Code ancestor = scratch.cellKeys[c] >> (3 * up);
            level = &widened[static_cast<std::size_t>(up)];
            if (ancestor != level->ancestor) {
                // The ancestor's cells are one run of the sorted cell list around c.
                std::size_t first = c, last = c + 1;
                while (first > 0 && (scratch.cellKeys[first - 1] >> (3 * up)) == ancestor) {
                    --first;
                }
                while (last < cells && (scratch.cellKeys[last] >> (3 * up)) == ancestor) {
                    ++last;
                }
                level->sum = {};
                for (std::size_t a = first; a < last; ++a) {
                    level->sum.add(scratch.cellMoments[a]);
                }
                level->ancestor = ancestor;
                level->estimate.reset();
            }
            moments = &level->sum;
            density = level->sum.count;
        }
        if (moments->count < kMinPointsPerEstimate && useRegion) {
            if (!regionSummed) {
                region = regionMoments(cloud, sparseRegion, origin);
                regionSummed = true;
            }
            moments = &region;
            density = static_cast<double>(sparseRegion.nodePoints);
            level = nullptr;
        }
        const double cellEdge = fineEdge * static_cast<double>(std::uint32_t{1} << up);
        std::optional<CellEstimate> own;
        std::optional<CellEstimate>& slot = level != nullptr ? level->estimate : own;
        if (!slot) {
            slot = estimateCell(*moments, density, cellEdge, nodeEdge, estimateNormals);
        }
        const CellEstimate estimate = *slot;
        const std::uint32_t first = scratch.cellFirst[c];
        const std::uint32_t cellPoints = scratch.cellFirst[c + 1] - first;
        std::fill_n(out.radii.begin() + first, cellPoints, encodeRadius(estimate.radius));
        if (estimateNormals) {
            std::fill_n(out.normals.begin() + first, cellPoints, estimate.normal);
        }
    }
}

} // namespace omicron
