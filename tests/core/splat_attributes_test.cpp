// Splat attributes: encodings, and the estimates on surfaces with known normal and spacing.
#include "hierarchy_test_support.hpp"
#include "splat_attributes.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace omicron {
namespace {

TEST(SplatAttributes, OctahedralNormalsRoundTrip) {
    std::mt19937_64 random(4);
    std::normal_distribution<float> gauss;
    for (int i = 0; i < 10000; ++i) {
        const glm::vec3 n = glm::normalize(glm::vec3(gauss(random), gauss(random), gauss(random)));
        const glm::vec3 back = decodeOctahedral(encodeOctahedral(n));
        EXPECT_GT(glm::dot(n, back), 0.99999f) << n.x << " " << n.y << " " << n.z;
    }
    for (const glm::vec3 axis :
         {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0)}) {
        EXPECT_GT(glm::dot(axis, decodeOctahedral(encodeOctahedral(axis))), 0.99999f);
    }
    EXPECT_EQ(encodeOctahedral(glm::vec3(0.0f)), kUnknownNormal);
    EXPECT_EQ(decodeOctahedral(kUnknownNormal), glm::vec3(0.0f));
}

TEST(SplatAttributes, RadiusEncodingIsWithinAQuarterPercent) {
    for (float r = 1e-9f; r < 1.0f; r *= 1.37f) {
        const float back = decodeRadius(encodeRadius(r));
        if (r < std::ldexp(1.0f, -32)) {
            EXPECT_FLOAT_EQ(back, std::ldexp(1.0f, -32)) << "clamped to the smallest code";
        } else {
            EXPECT_NEAR(back / r, 1.0f, 0.0025f) << r;
        }
    }
    EXPECT_EQ(encodeRadius(0.0f), 0u);
}

// A square grid of n x n points on the plane z = 0.5, spacing 1/n, plus a tiny jitter.
test::SyntheticCloud gridPlane(int n) {
    test::SyntheticCloud cloud;
    cloud.info.path = "grid plane";
    std::mt19937_64 random(9);
    std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            cloud.points.positions.push_back(
                glm::vec3((x + 0.5f + jitter(random)) / n, (y + 0.5f + jitter(random)) / n, 0.5f));
        }
    }
    cloud.info.pointCount = cloud.points.size();
    return cloud;
}

TEST(SplatAttributes, PlaneGetsItsNormalAndItsSpacing) {
    const int n = 512;
    const auto result = test::buildSynthetic(gridPlane(n), BuildOptions{}, 65536);
    const SplatAttributes& splats = result.builder->hierarchy().splats();
    ASSERT_TRUE(splats.estimatesNormals());
    std::vector<float> radii;
    std::size_t upright = 0;
    for (std::size_t i = 0; i < result.cloud->sortedEnd(); ++i) {
        upright += splats.normal(i).z > 0.999f ? 1 : 0;
        radii.push_back(splats.radius(i));
    }
    EXPECT_EQ(upright, radii.size()) << "every normal of a plane is its normal, facing +z";
    std::sort(radii.begin(), radii.end());
    const float spacing = 1.0f / n;
    EXPECT_NEAR(radii[radii.size() / 2] / spacing, 1.0f, 0.25f) << "median radius ~ spacing";
    EXPECT_GT(radii.front(), 0.5f * spacing);
    EXPECT_LT(radii.back(), 2.0f * spacing);
}

TEST(SplatAttributes, TiltedPlaneNormal) {
    // The plane x + y + z = 1.5 through the cube: normal (1, 1, 1) / sqrt(3).
    test::SyntheticCloud cloud = test::makeCloud(test::Shape::Random, 60000, 3);
    for (glm::vec3& p : cloud.points.positions) {
        p.z = std::clamp(1.5f - p.x - p.y, 0.0f, 1.0f);
    }
    cloud.info.attributes = {};
    cloud.points.attributes = {};
    cloud.points.colors.clear();
    const auto result = test::buildSynthetic(cloud, BuildOptions{}, 65536);
    const SplatAttributes& splats = result.builder->hierarchy().splats();
    const glm::vec3 expected = glm::normalize(glm::vec3(1.0f));
    std::size_t good = 0, onPlane = 0;
    for (std::size_t i = 0; i < result.cloud->sortedEnd(); ++i) {
        const glm::vec3 p = result.cloud->positions()[i];
        if (p.z <= 0.0f || p.z >= 1.0f) {
            continue; // clamped onto a cube face: another plane
        }
        ++onPlane;
        good += glm::dot(splats.normal(i), expected) > 0.99f ? 1 : 0;
    }
    EXPECT_GT(double(good), 0.95 * double(onPlane));
}

TEST(SplatAttributes, LineHasNoNormalButASpacing) {
    const auto result =
        test::buildSynthetic(test::makeCloud(test::Shape::Line, 20000, 5), BuildOptions{});
    const SplatAttributes& splats = result.builder->hierarchy().splats();
    for (std::size_t i = 0; i < result.cloud->sortedEnd(); i += 97) {
        EXPECT_EQ(splats.normal(i), glm::vec3(0.0f)) << "a line has no surface normal";
        EXPECT_GT(splats.radius(i), 0.0f);
        EXPECT_LT(splats.radius(i), 0.01f);
    }
}

TEST(SplatAttributes, CoincidentPointsGetHalfTheirCellAsRadius) {
    // Nothing to measure: the fallback is half the edge of the fine cell they fall in.
    const auto result =
        test::buildSynthetic(test::makeCloud(test::Shape::AllIdentical, 500, 5), BuildOptions{});
    const SplatAttributes& splats = result.builder->hierarchy().splats();
    const float halfLeafEdge = std::ldexp(1.0f, -(BuildOptions{}.maxLevel + 1));
    for (std::size_t i = 0; i < result.cloud->sortedEnd(); ++i) {
        EXPECT_GT(splats.radius(i), 0.0f);
        EXPECT_LE(splats.radius(i), halfLeafEdge * 1.001f);
        EXPECT_EQ(splats.normal(i), glm::vec3(0.0f));
    }
}

TEST(SplatAttributes, InputNormalsAreKept) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    const auto result = test::buildFile(path, BuildOptions{});
    const SplatAttributes& splats = result.builder->hierarchy().splats();
    EXPECT_FALSE(splats.estimatesNormals());
    EXPECT_EQ(splats.bytesPerPoint(), 2u);
    for (std::size_t i = 0; i < result.cloud->sortedEnd(); ++i) {
        ASSERT_EQ(splats.normal(i), result.cloud->normals()[i]);
        ASSERT_GT(splats.radius(i), 0.0f);
        ASSERT_TRUE(std::isfinite(splats.radius(i)));
    }
}

TEST(SplatAttributes, RealScanWithoutNormalsGetsUnitNormalsAlmostEverywhere) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.ply");
    const auto result = test::buildFile(path, BuildOptions{});
    const SplatAttributes& splats = result.builder->hierarchy().splats();
    EXPECT_TRUE(splats.estimatesNormals());
    EXPECT_EQ(splats.bytesPerPoint(), 6u);
    std::size_t known = 0;
    for (std::size_t i = 0; i < result.cloud->sortedEnd(); ++i) {
        const glm::vec3 n = splats.normal(i);
        if (n != glm::vec3(0.0f)) {
            ++known;
            ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
        }
        ASSERT_GT(splats.radius(i), 0.0f);
    }
    EXPECT_GT(double(known), 0.95 * double(result.cloud->sortedEnd()));
}

} // namespace
} // namespace omicron
