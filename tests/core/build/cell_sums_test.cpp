// A fine cell's sums in float lanes against the same moments summed point by point in double:
// the moments, and the centred covariance a splat estimate takes from them, agree for a small
// cell anywhere in the cube, for a cell of many runs, and for one of coincident points.
#include "build/cell_sums.hpp"

#include <cmath>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace omicron {
namespace {

SplatScratch::Moments doubleMoments(const std::vector<glm::vec3>& points,
                                    const glm::dvec3& origin) {
    SplatScratch::Moments m;
    for (const glm::vec3& p : points) {
        m.add(p.x - origin.x, p.y - origin.y, p.z - origin.z);
    }
    return m;
}

SplatScratch::Moments cellMoments(const std::vector<glm::vec3>& points, const glm::dvec3& origin) {
    CellSums sums(origin);
    sums.start(points.front());
    for (const glm::vec3& p : points) {
        sums.add(p);
    }
    return sums.moments();
}

// The centred covariance (xx, yy, zz, xy, xz, yz) of moments.
std::array<double, 6> covariance(const SplatScratch::Moments& m) {
    const double mx = m.sx / m.count, my = m.sy / m.count, mz = m.sz / m.count;
    return {m.sxx / m.count - mx * mx, m.syy / m.count - my * my, m.szz / m.count - mz * mz,
            m.sxy / m.count - mx * my, m.sxz / m.count - mx * mz, m.syz / m.count - my * mz};
}

// Points on a tilted patch of a cell of edge `edge` at `corner`, with some noise off it.
std::vector<glm::vec3> patch(const glm::dvec3& corner, double edge, std::size_t count,
                             unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<glm::vec3> points;
    for (std::size_t i = 0; i < count; ++i) {
        const double u = unit(random), v = unit(random);
        const double w = 0.3 * u + 0.2 * v + 0.01 * unit(random);
        points.emplace_back(corner + edge * glm::dvec3(u, v, w));
    }
    return points;
}

void expectSameMoments(const std::vector<glm::vec3>& points, const glm::dvec3& origin,
                       double edge) {
    const SplatScratch::Moments expected = doubleMoments(points, origin);
    const SplatScratch::Moments got = cellMoments(points, origin);
    EXPECT_EQ(got.count, expected.count);
    const double n = expected.count;
    // Sums of coordinates relative to the origin: within a float rounding of the cell's size
    // per point.
    const double reach = edge + 1e-3;
    const double sumTolerance = n * 1e-6 * reach;
    EXPECT_NEAR(got.sx, expected.sx, sumTolerance);
    EXPECT_NEAR(got.sy, expected.sy, sumTolerance);
    EXPECT_NEAR(got.sz, expected.sz, sumTolerance);
    // What an estimate uses: the covariance, to a small fraction of its size.
    const std::array<double, 6> a = covariance(expected), b = covariance(got);
    const double scale = a[0] + a[1] + a[2];
    ASSERT_GT(scale, 0.0);
    for (std::size_t k = 0; k < 6; ++k) {
        EXPECT_NEAR(b[k], a[k], 1e-4 * scale) << "covariance entry " << k;
    }
}

TEST(CellSums, MomentsOfASmallCellMatchDoubleSums) {
    // A level-10 cell (edge 2^-10) far from the node's corner, as in a leaf's fine cells.
    const double edge = std::ldexp(1.0, -10);
    const glm::dvec3 corner(0.61328125, 0.2001953125, 0.8876953125);
    const glm::dvec3 nodeCorner(0.5, 0.125, 0.875);
    expectSameMoments(patch(corner, edge, 40, 1), nodeCorner, edge);
}

TEST(CellSums, ACellOfManyRunsMatchesDoubleSums) {
    // More points than one float run holds: the runs are closed into double moments.
    const double edge = std::ldexp(1.0, -8);
    const glm::dvec3 corner(0.25, 0.5, 0.75);
    const std::size_t count = 3 * CellSums::kMaxRun + 17;
    expectSameMoments(patch(corner, edge, count, 2), glm::dvec3(0.0), edge);
    expectSameMoments(patch(corner, edge, count, 3), corner - glm::dvec3(edge), edge);
}

TEST(CellSums, CoincidentPointsHaveNoSpread) {
    const std::vector<glm::vec3> points(10000, glm::vec3(0.3f, 0.6f, 0.9f));
    const SplatScratch::Moments m = cellMoments(points, glm::dvec3(0.25, 0.5, 0.875));
    EXPECT_EQ(m.count, 10000.0);
    for (const double entry : covariance(m)) {
        EXPECT_NEAR(entry, 0.0, 1e-12);
    }
}

TEST(CellSums, StartingAgainForgetsThePreviousCell) {
    const glm::dvec3 origin(0.0);
    const std::vector<glm::vec3> first = patch(glm::dvec3(0.1), 0.01, 5000, 4);
    const std::vector<glm::vec3> second = patch(glm::dvec3(0.7), 0.01, 30, 5);
    CellSums sums(origin);
    sums.start(first.front());
    for (const glm::vec3& p : first) {
        sums.add(p);
    }
    sums.start(second.front());
    for (const glm::vec3& p : second) {
        sums.add(p);
    }
    const SplatScratch::Moments got = sums.moments();
    const SplatScratch::Moments expected = doubleMoments(second, origin);
    EXPECT_EQ(got.count, expected.count);
    EXPECT_NEAR(got.sx, expected.sx, 1e-6);
    EXPECT_NEAR(got.sxx, expected.sxx, 1e-6);
}

} // namespace
} // namespace omicron
