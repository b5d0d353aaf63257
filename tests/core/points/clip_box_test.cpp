// ClipBox: containment in its turned frame, the conservative cell test against sampled points,
// source -> unit cube, and File -> Export Points of a clipped view: exactly the points a brute
// force finds inside, for a box and a thin section.
#include "hierarchy_test_support.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/cloud_export.hpp"
#include "io/point_reader.hpp"
#include "points/clip_box.hpp"
#include "test_files.hpp"

#include <cmath>
#include <gtest/gtest.h>
#include <random>

namespace omicron {
namespace {

TEST(ClipBox, ContainsInItsTurnedFrame) {
    ClipBox box;
    box.center = {10.0, 20.0, 5.0};
    box.halfSize = {4.0, 1.0, 2.0};
    box.yawRadians = std::acos(-1.0) / 2.0; // its x axis along +y
    EXPECT_TRUE(box.contains({10.0, 23.9, 5.0}));  // 3.9 along its x
    EXPECT_FALSE(box.contains({13.0, 20.0, 5.0})); // 3 along its y (half size 1)
    EXPECT_TRUE(box.contains({10.9, 20.0, 6.9}));
    EXPECT_FALSE(box.contains({10.0, 20.0, 7.1}));
}

TEST(ClipBox, CellTestNeverDropsACellWithAPointInside) {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int culled = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        ClipBox box;
        box.center = {unit(random), unit(random), unit(random)};
        box.halfSize = {0.02 + 0.2 * unit(random), 0.02 + 0.2 * unit(random),
                        0.02 + 0.2 * unit(random)};
        box.yawRadians = 6.3 * unit(random);
        const double edge = 0.25 * unit(random) + 0.01;
        const glm::dvec3 min(unit(random), unit(random), unit(random));
        bool anyInside = false;
        for (int s = 0; s < 300 && !anyInside; ++s) {
            anyInside = box.contains(min + edge * glm::dvec3(unit(random), unit(random),
                                                            unit(random)));
        }
        const bool kept = box.intersects(min, edge);
        EXPECT_TRUE(kept || !anyInside) << "trial " << trial;
        culled += kept ? 0 : 1;
    }
    EXPECT_GT(culled, 500); // and it does cull
}

TEST(ClipBox, SourceUnitsToTheUnitCube) {
    const CubeTransform cube{{100.0, 200.0, 10.0}, 50.0};
    const ClipBox box{{125.0, 210.0, 20.0}, {5.0, 2.5, 1.0}, 0.3};
    const ClipBox unit = toUnitCube(box, cube);
    const glm::dvec3 p(128.0, 211.0, 20.5);
    EXPECT_EQ(box.contains(p), unit.contains((p - cube.origin) / cube.edge));
    EXPECT_NEAR(unit.halfSize.x, 0.1, 1e-12);
    EXPECT_NEAR(unit.yawRadians, 0.3, 1e-12);
}

class ClippedExport : public ::testing::TestWithParam<bool> {};

TEST_P(ClippedExport, WritesExactlyThePointsInside) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.las");
    const bool section = GetParam();
    const test::BuildResult built = test::buildFile(path, BuildOptions{});
    const SortedCloud& cloud = *built.cloud;
    const CubeTransform& cube = cloud.cube();
    ClipBox box;
    box.center = cube.origin + glm::dvec3(cube.edge * 0.4, cube.edge * 0.2, cube.edge * 0.05);
    box.yawRadians = 0.5;
    box.halfSize = section ? glm::dvec3(1.0, 1e9, 1e9) // a 2-unit section
                           : glm::dvec3(cube.edge * 0.15, cube.edge * 0.1, cube.edge);
    std::size_t inside = 0;
    for (std::size_t i = 0; i < cloud.sortedEnd(); ++i) {
        inside += box.contains(cube.toSource(cloud.position(i))) ? 1 : 0;
    }
    ASSERT_GT(inside, 100u);
    ASSERT_LT(inside, cloud.sortedEnd());
    test::TempDir dir;
    const std::string out = dir.file("clipped.las");
    EXPECT_EQ(exportCloudPoints(out, cloud, box), inside);
    const auto exported = loadPointCloud(out);
    EXPECT_EQ(exported.points.size(), inside);
    for (std::size_t i = 0; i < exported.points.size(); ++i) {
        const glm::dvec3 p = exported.info.cube.toSource(exported.points.positions[i]);
        // The LAS step is finer than a millimetre of these feet: inside within it.
        ClipBox grown = box;
        grown.halfSize += glm::dvec3(1e-3);
        ASSERT_TRUE(grown.contains(p)) << i;
    }
}

INSTANTIATE_TEST_SUITE_P(BoxAndSection, ClippedExport, ::testing::Bool());

TEST(ClippedExport, ABoxAroundNothingIsAnErrorNamingTheFile) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    const test::BuildResult built = test::buildFile(path, BuildOptions{});
    test::TempDir dir;
    const std::string out = dir.file("none.ply");
    const ClipBox far{{1e6, 1e6, 1e6}, {1.0, 1.0, 1.0}, 0.0};
    try {
        exportCloudPoints(out, *built.cloud, far);
        FAIL() << "expected an OutputError";
    } catch (const OutputError& error) {
        EXPECT_NE(std::string(error.what()).find(out), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("clip box"), std::string::npos) << error.what();
    }
}

} // namespace
} // namespace omicron
