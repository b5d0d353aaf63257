// BuildPipeline: pipelines 1 and 2 and the generated scene end to end, progress seen from
// another thread, rebuild from the kept sorted cloud without reading again, cancellation, and a
// bad file that leaves the previous hierarchy in place.
#include "formats/oms_writer.hpp"
#include "io/input_error.hpp"
#include "pipeline/build_pipeline.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <thread>
#include <vector>

namespace omicron {
namespace {

PipelineOptions smallOptions(int depth = 6) {
    PipelineOptions options;
    options.build.maxLevel = depth;
    options.build.checkInvariants = true;
    options.sortChunks = 8;
    return options;
}

void expectSameLevels(const BuildStatistics& a, const BuildStatistics& b) {
    ASSERT_EQ(a.levels.size(), b.levels.size());
    for (std::size_t level = 0; level < a.levels.size(); ++level) {
        EXPECT_EQ(a.levels[level].nodes, b.levels[level].nodes) << "level " << level;
        EXPECT_EQ(a.levels[level].leaves, b.levels[level].leaves) << "level " << level;
        EXPECT_EQ(a.levels[level].points, b.levels[level].points) << "level " << level;
    }
}

TEST(BuildPipeline, UnsortedCloudRunsPipelineOneToCompletion) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    BuildPipeline pipeline;
    EXPECT_EQ(pipeline.progress().phase, BuildPhase::Idle);
    EXPECT_EQ(pipeline.hierarchy(), nullptr);
    const PipelineResult result = pipeline.run(path, smallOptions());
    EXPECT_FALSE(result.cancelled);
    EXPECT_TRUE(result.stats.complete);
    EXPECT_TRUE(result.stats.invariantViolation.empty()) << result.stats.invariantViolation;
    EXPECT_EQ(result.source.kind, PipelineKind::UnsortedCloud);
    EXPECT_EQ(result.pipeline, "unsorted cloud -> incremental sorter -> builder");
    EXPECT_EQ(result.stats.inputPoints, result.source.pointCount);

    const PipelineProgress progress = pipeline.progress();
    EXPECT_EQ(progress.phase, BuildPhase::Complete);
    EXPECT_EQ(progress.pointsTotal, result.source.pointCount);
    EXPECT_EQ(progress.pointsRead, progress.pointsTotal);
    EXPECT_EQ(progress.pointsSorted, progress.pointsTotal);
    EXPECT_EQ(progress.pointsInserted, progress.pointsTotal);
    EXPECT_EQ(progress.cutDelimiter, morton::span(1, 6));
    ASSERT_NE(pipeline.hierarchy(), nullptr);
    EXPECT_TRUE(pipeline.hierarchy()->publishedCut().complete);
    EXPECT_TRUE(pipeline.hasCompleteCloud());
    EXPECT_EQ(pipeline.sourceReads(), 1u);
    EXPECT_TRUE(pipeline.preview().positions.empty()) << "the sorter is released after a run";

    // A complete build leaves one subtree in L_C: the root.
    EXPECT_EQ(result.stats.levels[0].cutRoots, 1u);
    for (std::size_t level = 1; level < result.stats.levels.size(); ++level) {
        EXPECT_EQ(result.stats.levels[level].cutRoots, 0u) << "level " << level;
    }
}

TEST(BuildPipeline, SortedStreamGivesTheSameHierarchyAsTheUnsortedCloud) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    test::TempDir dir;
    BuildPipeline first;
    const PipelineResult fromCloud = first.run(path, smallOptions());
    const std::string omsPath = dir.file("bunny.oms");
    const auto cloud = first.sortedCloud();
    writeOms(omsPath, *cloud, cloud->sortedEnd());

    BuildPipeline second;
    const PipelineResult fromStream = second.run(omsPath, smallOptions());
    EXPECT_EQ(fromStream.source.kind, PipelineKind::SortedStream);
    EXPECT_EQ(fromStream.pipeline, "sorted stream (.oms) -> builder");
    EXPECT_EQ(fromStream.sortSeconds, 0.0);
    expectSameLevels(fromCloud.stats, fromStream.stats);
    EXPECT_EQ(second.progress().pointsRead, fromCloud.source.pointCount);
}

TEST(BuildPipeline, RebuildReusesTheSortedCloudWithoutReading) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    BuildPipeline pipeline;
    pipeline.run(path, smallOptions(6));
    const auto cloudBefore = pipeline.sortedCloud();
    const auto hierarchyBefore = pipeline.hierarchy();

    BuildOptions other;
    other.maxLevel = 8;
    other.ratio = 0.3;
    other.collapse = LeafCollapse::Lossless;
    other.worklistSize = 8;
    other.checkInvariants = true;
    const PipelineResult rebuilt = pipeline.rebuild(other);
    EXPECT_EQ(pipeline.sourceReads(), 1u) << "rebuild must not read the file again";
    EXPECT_EQ(pipeline.sortedCloud(), cloudBefore);
    EXPECT_NE(pipeline.hierarchy(), hierarchyBefore);
    EXPECT_EQ(pipeline.hierarchy()->maxLevel(), 8);
    EXPECT_TRUE(rebuilt.stats.complete);
    EXPECT_TRUE(rebuilt.stats.invariantViolation.empty()) << rebuilt.stats.invariantViolation;

    // The same as building those options from the file.
    BuildPipeline fresh;
    PipelineOptions freshOptions;
    freshOptions.build = other;
    const PipelineResult reference = fresh.run(path, freshOptions);
    expectSameLevels(reference.stats, rebuilt.stats);
    EXPECT_EQ(reference.stats.placeholdersSubstituted, rebuilt.stats.placeholdersSubstituted);

    // Per-level substitutions add up to the total.
    std::uint64_t substituted = 0;
    for (const LevelStatistics& level : rebuilt.stats.levels) {
        substituted += level.placeholdersSubstituted;
    }
    EXPECT_EQ(substituted, rebuilt.stats.placeholdersSubstituted);
    EXPECT_GT(substituted, 0u) << "lossless collapse at depth 8 should substitute leaves";
}

TEST(BuildPipeline, RebuildWithoutACloudIsALogicError) {
    BuildPipeline pipeline;
    EXPECT_THROW(pipeline.rebuild(BuildOptions{}), std::logic_error);
}

TEST(BuildPipeline, BadOptionsAreRejectedBeforeReading) {
    BuildPipeline pipeline;
    PipelineOptions options;
    options.build.maxLevel = 0;
    EXPECT_THROW(pipeline.run("/nonexistent.ply", options), std::invalid_argument);
    EXPECT_EQ(pipeline.sourceReads(), 0u);
}

TEST(BuildPipeline, MalformedFileThrowsAndKeepsThePreviousHierarchy) {
    test::TempDir dir;
    BuildPipeline pipeline;
    pipeline.runGeneratedScene(20'000, 3, smallOptions());
    const auto hierarchyBefore = pipeline.hierarchy();
    const auto cloudBefore = pipeline.sortedCloud();
    ASSERT_NE(hierarchyBefore, nullptr);

    const std::string bad = dir.file("broken.ply");
    test::writeText(bad, "ply\nformat binary_little_endian 1.0\nelement vertex 10\n"
                         "property float x\nproperty float y\nproperty float z\nend_header\n"
                         "tooshort");
    try {
        pipeline.run(bad, smallOptions());
        FAIL() << "a truncated PLY was accepted";
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find(bad), std::string::npos) << error.what();
    }
    EXPECT_EQ(pipeline.progress().phase, BuildPhase::Failed);
    EXPECT_EQ(pipeline.hierarchy(), hierarchyBefore);
    EXPECT_EQ(pipeline.sortedCloud(), cloudBefore);
    EXPECT_EQ(pipeline.source()->kind, PipelineKind::GeneratedScene);
    EXPECT_TRUE(pipeline.hasCompleteCloud());
    // Still usable.
    EXPECT_TRUE(pipeline.rebuild(smallOptions(5).build).stats.complete);
}

TEST(BuildPipeline, ProgressSeenFromAnotherThreadOnlyGrows) {
    BuildPipeline pipeline;
    std::atomic<bool> done{false};
    std::vector<PipelineProgress> samples;
    std::thread poller([&] {
        while (!done.load()) {
            samples.push_back(pipeline.progress());
            (void)pipeline.preview();
            (void)pipeline.statistics();
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    });
    const PipelineResult result = pipeline.runGeneratedScene(300'000, 7, smallOptions(7));
    done.store(true);
    poller.join();
    samples.push_back(pipeline.progress());
    EXPECT_TRUE(result.stats.complete);
    ASSERT_GE(samples.size(), 2u);
    for (std::size_t i = 1; i < samples.size(); ++i) {
        const PipelineProgress& a = samples[i - 1];
        const PipelineProgress& b = samples[i];
        if (a.generation != b.generation) {
            continue;
        }
        EXPECT_LE(static_cast<int>(a.phase), static_cast<int>(b.phase)) << i;
        EXPECT_LE(a.pointsRead, b.pointsRead) << i;
        EXPECT_LE(a.pointsSorted, b.pointsSorted) << i;
        EXPECT_LE(a.pointsInserted, b.pointsInserted) << i;
        EXPECT_LE(a.cutDelimiter, b.cutDelimiter) << i;
        EXPECT_LE(b.pointsSorted, b.pointsTotal) << i;
    }
    EXPECT_EQ(samples.back().pointsInserted, 300'000u);
}

// A front end that draws nothing while reading (the CLI) turns the sorter's preview off: no
// point is ever sampled, and the hierarchy is the one built with it.
TEST(BuildPipeline, WithoutAPreviewNothingIsSampledAndTheHierarchyIsTheSame) {
    BuildPipeline withPreview;
    const PipelineResult reference = withPreview.runGeneratedScene(300'000, 7, smallOptions(7));

    BuildPipeline pipeline;
    PipelineOptions options = smallOptions(7);
    options.preview = false;
    std::atomic<bool> done{false};
    std::size_t largestPreview = 0;
    std::size_t polls = 0;
    std::thread poller([&] {
        while (!done.load()) {
            largestPreview = std::max(largestPreview, pipeline.preview().positions.size());
            ++polls;
            std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
    });
    const PipelineResult result = pipeline.runGeneratedScene(300'000, 7, options);
    done.store(true);
    poller.join();
    EXPECT_GT(polls, 0u);
    EXPECT_EQ(largestPreview, 0u);
    EXPECT_TRUE(result.stats.complete);
    expectSameLevels(reference.stats, result.stats);
}

TEST(BuildPipeline, CancelStopsARunPromptly) {
    BuildPipeline pipeline;
    std::thread canceller;
    const auto start = std::chrono::steady_clock::now();
    canceller = std::thread([&] {
        while (pipeline.progress().phase < BuildPhase::Reading) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        pipeline.cancel();
    });
    const PipelineResult result = pipeline.runGeneratedScene(1'500'000, 9, smallOptions(8));
    canceller.join();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_TRUE(result.cancelled);
    EXPECT_FALSE(result.stats.complete);
    EXPECT_EQ(pipeline.progress().phase, BuildPhase::Cancelled);
    EXPECT_FALSE(pipeline.hasCompleteCloud());
    EXPECT_THROW(pipeline.rebuild(BuildOptions{}), std::logic_error);
    EXPECT_LT(seconds, 30.0);
    // The request stays until reset; then the object is usable again.
    EXPECT_TRUE(pipeline.runGeneratedScene(10'000, 1, smallOptions()).cancelled);
    pipeline.resetCancel();
    EXPECT_TRUE(pipeline.runGeneratedScene(10'000, 1, smallOptions()).stats.complete);
}

} // namespace
} // namespace omicron
