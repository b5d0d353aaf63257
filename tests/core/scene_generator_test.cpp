// The built-in default cloud: exact size, determinism across runs and thread counts.
#include "scene_generator.hpp"

#include <cmath>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

namespace omicron {
namespace {

TEST(SceneGenerator, ExactCountEveryAttributeAndUnitCube) {
    const GeneratedScene scene = generateScene(123457, 1);
    ASSERT_EQ(scene.points.size(), 123457u);
    ASSERT_TRUE(scene.points.consistent());
    EXPECT_TRUE(scene.points.attributes.has(Attribute::Normal));
    EXPECT_TRUE(scene.points.attributes.has(Attribute::Color));
    for (std::size_t i = 0; i < scene.points.size(); ++i) {
        const glm::vec3& p = scene.points.positions[i];
        ASSERT_TRUE(p.x >= 0.0f && p.x <= 1.0f && p.y >= 0.0f && p.y <= 1.0f && p.z >= 0.0f &&
                    p.z <= 1.0f)
            << i;
        const glm::vec3& n = scene.points.normals[i];
        ASSERT_NEAR(std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z), 1.0f, 1e-4f) << i;
    }
    // A scene, not a box: it spans tens of metres at least.
    EXPECT_GT(scene.cube.edge, 50.0);
}

TEST(SceneGenerator, SameSeedSameCloudDifferentSeedDifferentCloud) {
    const GeneratedScene a = generateScene(50000, 7);
    const GeneratedScene b = generateScene(50000, 7);
    const GeneratedScene c = generateScene(50000, 8);
    EXPECT_EQ(a.points.positions, b.points.positions);
    EXPECT_EQ(a.points.colors, b.points.colors);
    EXPECT_EQ(a.cube, b.cube);
    EXPECT_NE(a.points.positions, c.points.positions);
}

TEST(SceneGenerator, IndependentOfThreadCount) {
    GeneratedScene one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = generateScene(300000, 3);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = generateScene(300000, 3);
    }
    EXPECT_EQ(one.points.positions, two.points.positions);
    EXPECT_EQ(one.points.normals, two.points.normals);
    EXPECT_EQ(one.points.colors, two.points.colors);
}

} // namespace
} // namespace omicron
