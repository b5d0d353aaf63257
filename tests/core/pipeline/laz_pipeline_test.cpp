// A LAZ file and the same points as uncompressed LAS give the same points and the same
// hierarchy: the LAZ reader is only another source of the LAS reader's records.
#include "io/point_reader.hpp"
#include "pipeline/build_pipeline.hpp"
#include "test_files.hpp"

#include <gtest/gtest.h>

namespace omicron {
namespace {

struct LazAndLas {
    const char* laz;
    const char* las;
};

class LazPipeline : public ::testing::TestWithParam<LazAndLas> {};

void PrintTo(const LazAndLas& pair, std::ostream* out) {
    *out << pair.laz << " vs " << pair.las;
}

TEST_P(LazPipeline, ReadsTheSamePointsAsTheUncompressedFile) {
    OMICRON_REQUIRE_SHARED_FILE(lazPath, GetParam().laz);
    OMICRON_REQUIRE_SHARED_FILE(lasPath, GetParam().las);
    const LoadedCloud laz = loadPointCloud(lazPath);
    const LoadedCloud las = loadPointCloud(lasPath);
    EXPECT_EQ(laz.info.format, CloudFormat::Laz);
    EXPECT_EQ(las.info.format, CloudFormat::Las);
    EXPECT_EQ(laz.info.attributes, las.info.attributes);
    EXPECT_EQ(laz.info.pointCount, las.info.pointCount);
    ASSERT_EQ(laz.points.size(), las.points.size());
    EXPECT_TRUE(laz.points.positions == las.points.positions);
    EXPECT_TRUE(laz.points.colors == las.points.colors);
    EXPECT_TRUE(laz.points.intensities == las.points.intensities);
}

TEST_P(LazPipeline, BuildsTheSameHierarchyAsTheUncompressedFile) {
    OMICRON_REQUIRE_SHARED_FILE(lazPath, GetParam().laz);
    OMICRON_REQUIRE_SHARED_FILE(lasPath, GetParam().las);
    PipelineOptions options;
    options.build.maxLevel = 7;
    options.build.checkInvariants = true;
    BuildPipeline fromLaz;
    const PipelineResult laz = fromLaz.run(lazPath, options);
    BuildPipeline fromLas;
    const PipelineResult las = fromLas.run(lasPath, options);
    EXPECT_TRUE(laz.stats.complete);
    EXPECT_TRUE(laz.stats.invariantViolation.empty()) << laz.stats.invariantViolation;
    EXPECT_EQ(laz.stats.inputPoints, las.stats.inputPoints);
    ASSERT_EQ(laz.stats.levels.size(), las.stats.levels.size());
    std::uint64_t nodes = 0;
    for (std::size_t level = 0; level < las.stats.levels.size(); ++level) {
        EXPECT_EQ(laz.stats.levels[level].nodes, las.stats.levels[level].nodes)
            << "level " << level;
        EXPECT_EQ(laz.stats.levels[level].leaves, las.stats.levels[level].leaves)
            << "level " << level;
        EXPECT_EQ(laz.stats.levels[level].points, las.stats.levels[level].points)
            << "level " << level;
        nodes += laz.stats.levels[level].nodes;
    }
    EXPECT_GT(nodes, 100u) << "a real hierarchy, not an empty one";
}

INSTANTIATE_TEST_SUITE_P(SharedLaz, LazPipeline,
                         ::testing::Values(LazAndLas{"laz/autzen_trim.laz", "autzen_trim.las"},
                                           LazAndLas{"laz/terrascan_fmt8.laz",
                                                     "laz/terrascan_fmt8.las"}),
                         [](const ::testing::TestParamInfo<LazAndLas>& info) {
                             return test::fileParamName(info.param.laz);
                         });

} // namespace
} // namespace omicron
