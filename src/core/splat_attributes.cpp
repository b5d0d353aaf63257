#include "splat_attributes.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>

namespace omicron {

namespace {

constexpr double kRadiusStepsPerOctave = 2048.0;
constexpr double kRadiusMinExponent = -32.0; // code 0 = 2^-32; 65535 ~ 2^0

// Fine cells hold about this many points on a surface (cells on a surface grow 4x per level).
constexpr double kPointsPerFineCell = 16.0;
// A cell with fewer points borrows the moments of its smallest ancestor cell with enough.
constexpr double kMinPointsPerEstimate = 8.0;
// Below this second invariant (relative to trace^2) a neighbourhood is a line or a point.
constexpr double kPlanarity = 1e-4;

std::int16_t toSnorm16(float v) {
    const float scaled = std::clamp(v, -1.0f, 1.0f) * 32767.0f;
    return static_cast<std::int16_t>(scaled + (scaled < 0.0f ? -0.5f : 0.5f));
}

float signNotZero(float v) {
    return v < 0.0f ? -1.0f : 1.0f;
}

// Fine-cell depth below the leaf: about kPointsPerFineCell points per cell on a surface.
int fineDepth(std::size_t points, int level) {
    const double ratio = static_cast<double>(points) / kPointsPerFineCell;
    const int depth = ratio <= 1.0 ? 0 : static_cast<int>(std::lround(0.5 * std::log2(ratio)));
    return std::clamp(depth, 0, morton::kMaxLevel - level);
}

struct CellEstimate {
    float radius = 0.0f;
    std::uint32_t normal = kUnknownNormal;
};

// Radius and normal from the covariance C of a cell's points, without an eigensolver (this
// runs for every 16 points of the cloud): the second invariant I2 = l1 l2 + l1 l3 + l2 l3 is
// l1 l2 on a surface (l3 ~ 0), and a uniform patch with sides a, b has l1 = a^2/12 and
// l2 = b^2/12, so its area is 12 sqrt(I2). The normal is the dominant eigenvector of the
// adjugate of C (eigenvalues l2 l3, l1 l3, l1 l2: largest for the smallest axis of C), from its
// largest column and two power steps.
CellEstimate estimateCell(const SplatScratch::Moments& m, double cellEdge, double leafEdge,
                          bool wantNormal) {
    const double k = m.count;
    const double inverse = 1.0 / k;
    const double mx = m.sx * inverse, my = m.sy * inverse, mz = m.sz * inverse;
    const double cxx = std::max(0.0, m.sxx * inverse - mx * mx);
    const double cyy = std::max(0.0, m.syy * inverse - my * my);
    const double czz = std::max(0.0, m.szz * inverse - mz * mz);
    const double cxy = m.sxy * inverse - mx * my;
    const double cxz = m.sxz * inverse - mx * mz;
    const double cyz = m.syz * inverse - my * mz;
    const double trace = cxx + cyy + czz;
    // Adjugate (cofactor matrix) of the symmetric C.
    const double a00 = cyy * czz - cyz * cyz, a11 = cxx * czz - cxz * cxz,
                 a22 = cxx * cyy - cxy * cxy;
    const double a01 = cxz * cyz - cxy * czz, a02 = cxy * cyz - cxz * cyy,
                 a12 = cxy * cxz - cxx * cyz;
    const double secondInvariant = std::max(0.0, a00 + a11 + a22);
    const bool planar = k >= 3.0 && trace > 0.0 && secondInvariant > kPlanarity * trace * trace;

    CellEstimate estimate;
    double radius;
    if (planar) {
        radius = std::sqrt(12.0 * std::sqrt(secondInvariant) / k);
    } else if (trace > 0.0) {
        radius = std::sqrt(12.0 * trace) / k; // points along a line: their spacing
    } else {
        radius = 0.5 * cellEdge; // coincident points: nothing to measure
    }
    constexpr double kMinRadius = 1.0 / double(std::uint64_t{1} << 22); // half a level-21 cell
    estimate.radius = static_cast<float>(std::clamp(radius, kMinRadius, leafEdge));
    if (!wantNormal || !planar) {
        return estimate;
    }
    glm::dvec3 v = a00 >= a11 && a00 >= a22 ? glm::dvec3(a00, a01, a02)
                   : a11 >= a22             ? glm::dvec3(a01, a11, a12)
                                            : glm::dvec3(a02, a12, a22);
    for (int step = 0; step < 2; ++step) {
        const double length = std::sqrt(glm::dot(v, v));
        if (!(length > 0.0)) {
            return estimate;
        }
        v /= length;
        v = glm::dvec3(a00 * v.x + a01 * v.y + a02 * v.z, a01 * v.x + a11 * v.y + a12 * v.z,
                       a02 * v.x + a12 * v.y + a22 * v.z);
    }
    const double length = std::sqrt(glm::dot(v, v));
    if (!(length > 0.0) || !std::isfinite(length)) {
        return estimate;
    }
    glm::vec3 n(v / length);
    // PCA gives no side; up (+z) is the common convention for scans (terrain, buildings).
    if (n.z < 0.0f) {
        n = -n;
    }
    estimate.normal = encodeOctahedral(n);
    return estimate;
}

} // namespace

std::uint32_t encodeOctahedral(const glm::vec3& unitNormal) {
    const float sum = std::abs(unitNormal.x) + std::abs(unitNormal.y) + std::abs(unitNormal.z);
    if (!(sum > 0.0f)) {
        return kUnknownNormal;
    }
    float x = unitNormal.x / sum, y = unitNormal.y / sum;
    if (unitNormal.z < 0.0f) {
        const float fx = (1.0f - std::abs(y)) * signNotZero(x);
        const float fy = (1.0f - std::abs(x)) * signNotZero(y);
        x = fx;
        y = fy;
    }
    return static_cast<std::uint16_t>(toSnorm16(x)) |
           static_cast<std::uint32_t>(static_cast<std::uint16_t>(toSnorm16(y))) << 16;
}

glm::vec3 decodeOctahedral(std::uint32_t encoded) {
    if (encoded == kUnknownNormal) {
        return glm::vec3(0.0f);
    }
    const float x = static_cast<float>(static_cast<std::int16_t>(encoded & 0xffffu)) / 32767.0f;
    const float y = static_cast<float>(static_cast<std::int16_t>(encoded >> 16)) / 32767.0f;
    glm::vec3 v(x, y, 1.0f - std::abs(x) - std::abs(y));
    if (v.z < 0.0f) {
        const float fx = (1.0f - std::abs(y)) * signNotZero(x);
        const float fy = (1.0f - std::abs(x)) * signNotZero(y);
        v.x = fx;
        v.y = fy;
    }
    return glm::normalize(v);
}

std::uint16_t encodeRadius(float radius) {
    if (!(radius > 0.0f)) {
        return 0;
    }
    // float log2 is exact enough: one code step is 1/2048 octave.
    const float code = (std::log2(radius) - static_cast<float>(kRadiusMinExponent)) *
                       static_cast<float>(kRadiusStepsPerOctave);
    return static_cast<std::uint16_t>(std::clamp(code, 0.0f, 65535.0f) + 0.5f);
}

float decodeRadius(std::uint16_t encoded) {
    return static_cast<float>(
        std::exp2(static_cast<double>(encoded) / kRadiusStepsPerOctave + kRadiusMinExponent));
}

void SplatScratch::Moments::add(const Moments& o) {
    count += o.count;
    sx += o.sx;
    sy += o.sy;
    sz += o.sz;
    sxx += o.sxx;
    sxy += o.sxy;
    sxz += o.sxz;
    syy += o.syy;
    syz += o.syz;
    szz += o.szz;
}

SplatAttributes::SplatAttributes(const SortedCloud& cloud)
    : m_cloud(cloud), m_capacity(cloud.capacity()),
      m_radii(std::make_unique_for_overwrite<std::uint16_t[]>(m_capacity)),
      m_normals(cloud.attributes().has(Attribute::Normal)
                    ? nullptr
                    : std::make_unique_for_overwrite<std::uint32_t[]>(m_capacity)) {}

glm::vec3 SplatAttributes::normal(std::size_t point) const {
    return estimatesNormals() ? decodeOctahedral(m_normals[point]) : m_cloud.normals()[point];
}

void SplatAttributes::estimateLeaf(std::size_t begin, std::size_t end, int level,
                                   std::size_t parentBegin, std::size_t parentEnd,
                                   SplatScratch& scratch) {
    assert(parentBegin <= begin && begin <= end && end <= parentEnd);
    if (begin == end) {
        return;
    }
    const std::span<const morton::Code> codes = m_cloud.codes();
    const std::span<const glm::vec3> positions = m_cloud.positions();
    const int depth = fineDepth(end - begin, level);
    const int fineLevel = level + depth;
    const int shift = 3 * (morton::kMaxLevel - fineLevel);
    const double leafEdge = std::ldexp(1.0, -level);
    const double fineEdge = std::ldexp(1.0, -fineLevel);
    const morton::Cell leafCell = morton::decode(codes[begin] >> (3 * (morton::kMaxLevel - level)));
    // Moments relative to the leaf's corner keep the double sums well conditioned.
    const glm::dvec3 origin = glm::dvec3(leafCell.x, leafCell.y, leafCell.z) * leafEdge;

    scratch.cellKeys.clear();
    scratch.cellFirst.clear();
    scratch.cellMoments.clear();
    // Sums stay in registers while a cell lasts (appending through the vector each point
    // would force them through memory).
    SplatScratch::Moments current;
    morton::Code currentKey = codes[begin] >> shift;
    std::size_t currentFirst = begin;
    for (std::size_t i = begin; i < end; ++i) {
        const morton::Code key = codes[i] >> shift;
        if (key != currentKey) {
            scratch.cellKeys.push_back(currentKey);
            scratch.cellFirst.push_back(static_cast<std::uint32_t>(currentFirst));
            scratch.cellMoments.push_back(current);
            current = {};
            currentKey = key;
            currentFirst = i;
        }
        current.add(glm::dvec3(positions[i]) - origin);
    }
    scratch.cellKeys.push_back(currentKey);
    scratch.cellFirst.push_back(static_cast<std::uint32_t>(currentFirst));
    scratch.cellMoments.push_back(current);
    scratch.cellFirst.push_back(static_cast<std::uint32_t>(end));
    // A leaf too sparse for an estimate of its own borrows its sibling group's points.
    bool parentSummed = false;
    SplatScratch::Moments parent;
    const auto parentMoments = [&]() -> const SplatScratch::Moments& {
        if (!parentSummed) {
            for (std::size_t i = parentBegin; i < parentEnd; ++i) {
                parent.add(glm::dvec3(positions[i]) - origin);
            }
            parentSummed = true;
        }
        return parent;
    };

    const bool wantNormals = estimatesNormals();
    const std::size_t cells = scratch.cellKeys.size();
    // The widened estimate of the last sparse cell: its neighbours in Morton order usually
    // share the same ancestor, so the sum is reused.
    int cachedUp = -1;
    morton::Code cachedAncestor = 0;
    SplatScratch::Moments cached;
    for (std::size_t c = 0; c < cells; ++c) {
        const SplatScratch::Moments* moments = &scratch.cellMoments[c];
        int up = 0;
        while (moments->count < kMinPointsPerEstimate && up < depth) {
            ++up;
            const morton::Code ancestor = scratch.cellKeys[c] >> (3 * up);
            if (up != cachedUp || ancestor != cachedAncestor) {
                // The ancestor's cells are one run of the sorted cell list around c.
                std::size_t first = c, last = c + 1;
                while (first > 0 && (scratch.cellKeys[first - 1] >> (3 * up)) == ancestor) {
                    --first;
                }
                while (last < cells && (scratch.cellKeys[last] >> (3 * up)) == ancestor) {
                    ++last;
                }
                cached = {};
                for (std::size_t a = first; a < last; ++a) {
                    cached.add(scratch.cellMoments[a]);
                }
                cachedUp = up;
                cachedAncestor = ancestor;
            }
            moments = &cached;
        }
        if (moments->count < kMinPointsPerEstimate && parentEnd - parentBegin > end - begin) {
            moments = &parentMoments();
            ++up;
        }
        const double cellEdge = fineEdge * static_cast<double>(std::uint32_t{1} << up);
        const CellEstimate estimate = estimateCell(*moments, cellEdge, leafEdge, wantNormals);
        const std::size_t first = scratch.cellFirst[c];
        const std::size_t count = scratch.cellFirst[c + 1] - first;
        std::fill_n(m_radii.get() + first, count, encodeRadius(estimate.radius));
        if (wantNormals) {
            std::fill_n(m_normals.get() + first, count, estimate.normal);
        }
    }
}

} // namespace omicron
