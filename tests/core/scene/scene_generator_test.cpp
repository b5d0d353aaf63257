// The procedural default scene: exact counts, bit-identical output for a seed whatever the
// thread count, unit normals, positions in the unit cube, and a scanner-like density.
#include "scene/scene_generator.hpp"

#include <cstring>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

namespace omicron {
namespace {

template <typename Column> bool sameBytes(const Column& a, const Column& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

bool identical(const GeneratedScene& a, const GeneratedScene& b) {
    return sameBytes(a.points.positions, b.points.positions) &&
           sameBytes(a.points.normals, b.points.normals) &&
           sameBytes(a.points.colors, b.points.colors) && a.cube == b.cube &&
           a.sourceBounds == b.sourceBounds;
}

TEST(SceneGenerator, PointCountIsExact) {
    // Around the 4096-point generator blocks, and one point.
    for (const std::uint64_t count : {1u, 4095u, 4096u, 4097u, 12345u}) {
        const GeneratedScene scene = generateScene(count, 1);
        EXPECT_EQ(scene.points.size(), count);
        EXPECT_TRUE(scene.points.consistent());
        EXPECT_EQ(scene.points.attributes, AttributeSet(Attribute::Normal) | Attribute::Color);
    }
}

TEST(SceneGenerator, SameSeedGivesBitIdenticalPoints) {
    EXPECT_TRUE(identical(generateScene(30'000, 42), generateScene(30'000, 42)));
}

TEST(SceneGenerator, DifferentSeedsGiveDifferentPoints) {
    const GeneratedScene a = generateScene(30'000, 1);
    const GeneratedScene b = generateScene(30'000, 2);
    EXPECT_FALSE(sameBytes(a.points.positions, b.points.positions));
    EXPECT_FALSE(sameBytes(a.points.colors, b.points.colors));
}

TEST(SceneGenerator, PrefixOfALargerSceneIsTheSmallerScene) {
    // Blocks are seeded by index, so a larger count only appends points (in source units).
    const GeneratedScene small = generateScene(10'000, 5);
    const GeneratedScene large = generateScene(20'000, 5);
    EXPECT_TRUE(std::equal(small.points.colors.begin(), small.points.colors.end(),
                           large.points.colors.begin()));
}

TEST(SceneGenerator, IndependentOfThreadCount) {
    GeneratedScene oneThread;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        oneThread = generateScene(100'000, 7);
    }
    GeneratedScene twoThreads;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        twoThreads = generateScene(100'000, 7);
    }
    EXPECT_TRUE(identical(oneThread, twoThreads));
}

TEST(SceneGenerator, NormalsHaveUnitLength) {
    const GeneratedScene scene = generateScene(50'000, 3);
    for (const glm::vec3& normal : scene.points.normals) {
        ASSERT_NEAR(glm::length(normal), 1.0f, 1e-5f);
    }
}

TEST(SceneGenerator, PositionsFillTheUnitCube) {
    const GeneratedScene scene = generateScene(50'000, 3);
    glm::vec3 low(1.0f), high(0.0f);
    for (const glm::vec3& p : scene.points.positions) {
        for (int c = 0; c < 3; ++c) {
            ASSERT_GE(p[c], 0.0f);
            ASSERT_LE(p[c], 1.0f);
        }
        low = glm::min(low, p);
        high = glm::max(high, p);
    }
    EXPECT_EQ(low, glm::vec3(0.0f));                     // the min corner is the origin
    EXPECT_EQ(std::max({high.x, high.y, high.z}), 1.0f); // the largest axis spans [0, 1]
    EXPECT_EQ(scene.cube, CubeTransform::fromBounds(scene.sourceBounds));
    // A few hundred metres of terrain, a few tens of metres of relief.
    const glm::dvec3 extent = scene.sourceBounds.extent();
    EXPECT_GT(extent.x, 250.0);
    EXPECT_LT(extent.x, 350.0);
    EXPECT_GT(extent.z, 15.0);
    EXPECT_LT(extent.z, 60.0);
}

TEST(SceneGenerator, DensityFallsWithDistanceFromTheScanner) {
    const GeneratedScene scene = generateScene(200'000, 9);
    // Points per square metre (horizontal) near the scanner at the origin and far from it.
    std::size_t near = 0, far = 0;
    for (const glm::vec3& unit : scene.points.positions) {
        const glm::dvec3 p = scene.cube.toSource(unit);
        const double range = std::hypot(p.x, p.y);
        near += range < 10.0 ? 1 : 0;
        far += range > 100.0 && range < 110.0 ? 1 : 0;
    }
    const double pi = 3.14159265358979;
    const double nearDensity = near / (pi * 10.0 * 10.0);
    const double farDensity = far / (pi * (110.0 * 110.0 - 100.0 * 100.0));
    EXPECT_GT(nearDensity, 20.0 * farDensity);
    EXPECT_GT(far, 0u);
}

TEST(SceneGenerator, SceneHasGroundWallsAndRoofs) {
    const GeneratedScene scene = generateScene(100'000, 4);
    std::size_t upward = 0, vertical = 0, high = 0;
    for (std::size_t i = 0; i < scene.points.size(); ++i) {
        const glm::vec3& n = scene.points.normals[i];
        upward += n.z > 0.9f ? 1 : 0;
        vertical += std::abs(n.z) < 0.1f ? 1 : 0;
        high += scene.cube.toSource(scene.points.positions[i]).z > 20.0 ? 1 : 0;
    }
    EXPECT_GT(upward, scene.points.size() / 2);    // terrain, roofs, pedestal top
    EXPECT_GT(vertical, scene.points.size() / 10); // walls, trunks, the statue's sides
    EXPECT_GT(high, 0u);                           // the tall buildings
}

} // namespace
} // namespace omicron
