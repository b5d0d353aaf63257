// Pipeline 1 under a memory budget that forces the sort onto disk: the hierarchy equals the
// in-memory build node for node (structure, held points, splats) for the shared scans, the
// adversarial shapes and the generated scene, with the invariants checked after every pass;
// the runs are gone after the build and after a cancel.
#include "formats/omh_writer.hpp"
#include "formats/oms_writer.hpp"
#include "hierarchy_test_support.hpp"
#include "io/ply/ply_writer.hpp"
#include "memory_budget.hpp"
#include "pipeline/build_pipeline.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <gtest/gtest.h>
#include <string>
#include <thread>

namespace omicron {
namespace {

PipelineOptions options(std::uint64_t budget, const std::string& tempDir,
                        LeafCollapse collapse = LeafCollapse::Off) {
    PipelineOptions o;
    o.build.maxLevel = 7;
    o.build.collapse = collapse;
    o.build.checkInvariants = true;
    o.memoryBudgetBytes = budget;
    o.tempDir = tempDir;
    return o;
}

std::size_t entriesIn(const std::filesystem::path& folder) {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(folder), {}));
}

struct Built {
    PipelineResult result;
    std::uint64_t print = 0;
    bool fileBacked = false; // the sorted cloud lived in a scratch file
};

Built build(const std::string& path, const PipelineOptions& o, bool withSplats) {
    BuildPipeline pipeline;
    Built built;
    built.result = pipeline.run(path, o);
    EXPECT_TRUE(built.result.stats.complete);
    EXPECT_TRUE(built.result.stats.invariantViolation.empty())
        << built.result.stats.invariantViolation;
    built.print = test::fingerprint(*pipeline.hierarchy(), withSplats);
    built.fileBacked = pipeline.sortedCloud() && pipeline.sortedCloud()->fileBacked();
    return built;
}

void expectSameBuild(const std::string& path, LeafCollapse collapse, bool withSplats) {
    test::TempDir scratch;
    const Built inMemory = build(path, options(0, scratch.path().string(), collapse), withSplats);
    EXPECT_EQ(inMemory.result.sortRuns, 0u);
    const Built spilled =
        build(path, options(kMinMemoryBudget, scratch.path().string(), collapse), withSplats);
    EXPECT_GT(spilled.result.sortRuns, 1u);
    EXPECT_FALSE(inMemory.fileBacked);
    // Sorted points over half the budget go to a scratch file (positions alone: 12 bytes).
    if (spilled.result.stats.inputPoints * sizeof(glm::vec3) > kMinMemoryBudget / 2) {
        EXPECT_TRUE(spilled.fileBacked) << "the sorted points stayed in memory beyond the budget";
    }
    EXPECT_EQ(spilled.print, inMemory.print) << "the hierarchies differ";
    ASSERT_EQ(spilled.result.stats.levels.size(), inMemory.result.stats.levels.size());
    for (std::size_t level = 0; level < inMemory.result.stats.levels.size(); ++level) {
        EXPECT_EQ(spilled.result.stats.levels[level].nodes,
                  inMemory.result.stats.levels[level].nodes);
        EXPECT_EQ(spilled.result.stats.levels[level].points,
                  inMemory.result.stats.levels[level].points);
    }
    EXPECT_EQ(entriesIn(scratch.path()), 0u) << "the runs outlived the build";
}

class BudgetedBuild : public testing::TestWithParam<std::string> {};

TEST_P(BudgetedBuild, SpilledSortBuildsTheSameHierarchyNodeForNode) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    expectSameBuild(path, LeafCollapse::Off, GetParam() == "lion.ply");
}

INSTANTIATE_TEST_SUITE_P(Files, BudgetedBuild,
                         testing::Values("autzen_trim.las", "lion.ply", "dragon.ply",
                                         "sorvilier.ply", "indoor.ply"),
                         test::FileParamName{});

TEST(BudgetedBuild, PaperCollapseToo) {
    OMICRON_REQUIRE_SHARED_FILE(path, "dragon.ply");
    expectSameBuild(path, LeafCollapse::Paper, false);
}

class BudgetedBuildShapes : public testing::TestWithParam<test::Shape> {};

TEST_P(BudgetedBuildShapes, AdversarialCloudsBuildTheSameHierarchy) {
    const test::SyntheticCloud cloud = test::makeCloud(GetParam(), 250'000, 11);
    test::TempDir dir;
    const std::string path = dir.file("cloud.ply");
    writePly(path, cloud.points, CubeTransform{glm::dvec3(0.0), 100.0});
    expectSameBuild(path, LeafCollapse::Off, false);
}

INSTANTIATE_TEST_SUITE_P(Shapes, BudgetedBuildShapes,
                         testing::Values(test::Shape::Random, test::Shape::Duplicates,
                                         test::Shape::AllIdentical, test::Shape::TwoClusters,
                                         test::Shape::MaxFaces, test::Shape::Plane,
                                         test::Shape::Line),
                         [](const auto& info) {
                             std::string name = test::toString(info.param);
                             std::replace(name.begin(), name.end(), ' ', '_');
                             return name;
                         });

TEST(BudgetedBuild, GeneratedSceneSpillsTheSame) {
    test::TempDir scratch;
    BuildPipeline inMemory;
    inMemory.runGeneratedScene(400'000, 5, options(0, scratch.path().string()));
    BuildPipeline spilled;
    const PipelineResult result =
        spilled.runGeneratedScene(400'000, 5, options(kMinMemoryBudget, scratch.path().string()));
    EXPECT_GT(result.sortRuns, 1u);
    EXPECT_EQ(test::fingerprint(*spilled.hierarchy(), false),
              test::fingerprint(*inMemory.hierarchy(), false));
    EXPECT_EQ(entriesIn(scratch.path()), 0u);
}

// Pipeline 2 beyond the budget: a sorted stream whose points exceed half of it streams into
// a file-backed cloud, and the hierarchy is the in-memory one.
TEST(BudgetedBuild, ASortedStreamBeyondTheBudgetStreamsIntoAFileBackedCloud) {
    OMICRON_REQUIRE_SHARED_FILE(path, "lion.ply");
    test::TempDir scratch;
    const std::string oms = scratch.file("lion.oms");
    {
        BuildPipeline sorter;
        sorter.run(path, options(0, scratch.path().string()));
        writeOms(oms, *sorter.sortedCloud(), sorter.sortedCloud()->sortedEnd());
    }
    const Built inMemory = build(oms, options(0, scratch.path().string()), true);
    EXPECT_FALSE(inMemory.fileBacked);
    const Built budgeted = build(oms, options(kMinMemoryBudget, scratch.path().string()), true);
    EXPECT_TRUE(budgeted.fileBacked);
    EXPECT_EQ(budgeted.print, inMemory.print);
    EXPECT_EQ(entriesIn(scratch.path()), 1u) << "only the .oms: the cloud's file has no name";
}

// A save over a cloud in a scratch file writes the in-memory build's bytes, whether the top
// levels' points are copied out while the sweep reads the file (whatever their size) or read
// in place, for sweep batches from one point (every level but the deepest above the sweep) to
// the whole hierarchy, and with leaves collapsed (a collapsed leaf's points lie under no swept
// subtree: they are copied between two batches' stretches).
TEST(BudgetedBuild, SaveOverTheScratchFileWritesTheInMemoryBytes) {
    OMICRON_REQUIRE_SHARED_FILE(path, "lion.ply");
    test::TempDir scratch;
    for (const LeafCollapse collapse : {LeafCollapse::Off, LeafCollapse::Paper}) {
        SCOPED_TRACE(collapse == LeafCollapse::Off ? "no collapse" : "paper collapse");
        BuildPipeline inMemory;
        const PipelineResult run =
            inMemory.run(path, options(0, scratch.path().string(), collapse));
        const omh::BuildInfo info = omhBuildInfo(options(0, "", collapse).build, run.stats);
        const std::string reference = scratch.file("reference.omh");
        writeOmh(reference, *inMemory.hierarchy(), info);
        BuildPipeline budgeted;
        budgeted.run(path, options(kMinMemoryBudget, scratch.path().string(), collapse));
        ASSERT_TRUE(budgeted.sortedCloud()->fileBacked());
        for (const bool gather : {true, false}) {
            for (const std::uint64_t batch : {std::uint64_t{1}, std::uint64_t{5'000},
                                              std::uint64_t{0}, std::uint64_t{1} << 40}) {
                SCOPED_TRACE(std::string(gather ? "gathered" : "in place") + ", batch " +
                             std::to_string(batch));
                OmhWriteOptions write;
                write.gatherTopLevels = gather;
                write.sweepBatchPoints = batch;
                std::vector<int> levelsWritten;
                write.afterLevel = [&](int level) {
                    levelsWritten.push_back(level);
                };
                writeOmh(scratch.file("budgeted.omh"), *budgeted.hierarchy(), info, write);
                EXPECT_EQ(test::readBytes(scratch.file("budgeted.omh")),
                          test::readBytes(reference));
                if (gather && batch == 1) {
                    // Every parent is above the sweep: their points are a quarter of the
                    // cloud, far beyond a quarter of the 4 MiB budget, and are still copied
                    // (written after the swept deepest level), never read in place.
                    ASSERT_FALSE(levelsWritten.empty());
                    EXPECT_EQ(levelsWritten.front(), 7);
                }
                std::sort(levelsWritten.begin(), levelsWritten.end());
                EXPECT_EQ(levelsWritten, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
            }
        }
    }
}

// Cancelled while the runs are merged into the builder: the run returns cancelled, and the
// runs are removed with the sorter.
TEST(BudgetedBuild, CancelDuringTheMergeRemovesTheRuns) {
    OMICRON_REQUIRE_SHARED_FILE(path, "indoor.ply");
    test::TempDir scratch;
    BuildPipeline pipeline;
    std::atomic<bool> stop{false};
    std::thread canceller([&] {
        while (!stop.load()) {
            if (pipeline.progress().phase == BuildPhase::Sorting) {
                pipeline.cancel();
                return;
            }
            std::this_thread::yield();
        }
    });
    const PipelineResult result =
        pipeline.run(path, options(kMinMemoryBudget, scratch.path().string()));
    stop.store(true);
    canceller.join();
    EXPECT_TRUE(result.cancelled);
    EXPECT_EQ(entriesIn(scratch.path()), 0u);
}

} // namespace
} // namespace omicron
