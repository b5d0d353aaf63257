// The bounds pre-pass of PLY and XYZ files, and of LAS files whose header bounds are unusable
// (a whole read of the file before any point is delivered), reports its progress per block and
// stops at the next block once cancelled, for every layout that has one; BuildPipeline passes its
// cancel flag to it, so cancel() during the pre-pass ends the run as cancelled with the previous
// cloud and hierarchy kept. Cancellation is observed through the progress reports (bytes scanned),
// never through time.
#include "io/las/las_header.hpp"
#include "io/las/las_writer.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "io/xyz/xyz_writer.hpp"
#include "pipeline/build_pipeline.hpp"
#include "scene/scene_generator.hpp"
#include "test_files.hpp"

#include <atomic>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <limits>
#include <string>
#include <vector>

namespace omicron {
namespace {

struct PrePassCase {
    const char* name;
    const char* file;
    PlyEncoding encoding; // ignored for .xyz and .las
};

// 100k generated points: 2.7 MB of binary PLY (1 MiB blocks), 7 MB and more of text; LAS
// (4 MiB blocks) gets 300k points, 10 MB, and a NaN in its header's bounds, which is what
// makes a LAS reader scan for bounds.
std::string writeCase(const test::TempDir& dir, const PrePassCase& param) {
    const std::string path = dir.file(param.file);
    const std::string extension = std::filesystem::path(path).extension().string();
    const GeneratedScene scene = generateScene(extension == ".las" ? 300'000 : 100'000, 5);
    if (extension == ".xyz") {
        writeXyz(path, scene.points, scene.cube);
    } else if (extension == ".las") {
        writeLas(path, scene.points, scene.cube);
        std::vector<std::uint8_t> bytes = test::readBytes(path);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        std::memcpy(bytes.data() + las::field::bounds + 32, &nan, sizeof nan); // max z
        test::writeBytes(path, bytes);
    } else {
        PlyWriteOptions options;
        options.encoding = param.encoding;
        writePly(path, scene.points, scene.cube, options);
    }
    return path;
}

class PrePass : public testing::TestWithParam<PrePassCase> {};

TEST_P(PrePass, ReportsEveryBlockUpToTheFileSize) {
    test::TempDir dir;
    const std::string path = writeCase(dir, GetParam());
    const std::uint64_t fileBytes = std::filesystem::file_size(path);
    std::vector<std::uint64_t> reports;
    OpenOptions options;
    options.onPrePassProgress = [&](std::uint64_t scanned, std::uint64_t total) {
        EXPECT_EQ(total, fileBytes);
        reports.push_back(scanned);
    };
    const auto reader = openPointCloud(path, options);
    EXPECT_FALSE(reader->info().boundsFromHeader);
    ASSERT_GE(reports.size(), 3u) << "a start, at least one block, the end";
    EXPECT_EQ(reports.back(), fileBytes);
    for (std::size_t i = 1; i < reports.size(); ++i) {
        EXPECT_LE(reports[i - 1], reports[i]) << i;
    }
}

TEST_P(PrePass, CancelStopsTheScanBeforeTheEndOfTheFile) {
    test::TempDir dir;
    const std::string path = writeCase(dir, GetParam());
    const std::uint64_t fileBytes = std::filesystem::file_size(path);
    std::atomic<bool> cancel{false};
    std::vector<std::uint64_t> reports;
    std::size_t reportsWhenCancelled = 0;
    OpenOptions options;
    options.cancel = &cancel;
    options.onPrePassProgress = [&](std::uint64_t scanned, std::uint64_t) {
        reports.push_back(scanned);
        // The first report is the scan's start, the second follows the first block: cancel
        // there, as a GUI's Cancel would, in the middle of the scan.
        if (reports.size() == 2) {
            cancel.store(true);
            reportsWhenCancelled = reports.size();
        }
    };
    try {
        openPointCloud(path, options);
        FAIL() << "the pre-pass ran to the end although cancelled";
    } catch (const OpenCancelled& cancelled) {
        EXPECT_EQ(cancelled.path(), path);
        EXPECT_LT(cancelled.bytesScanned(), fileBytes);
        EXPECT_NE(std::string(cancelled.what()).find(path), std::string::npos);
    }
    ASSERT_GT(reportsWhenCancelled, 0u);
    EXPECT_EQ(reports.size(), reportsWhenCancelled) << "the scan went on after the cancel";
    EXPECT_LT(reports.back(), fileBytes);
}

INSTANTIATE_TEST_SUITE_P(
    Layouts, PrePass,
    testing::Values(PrePassCase{"PlyBinaryFloat", "scene.ply", PlyEncoding::BinaryLittleEndian},
                    PrePassCase{"PlyBinarySwapped", "scene.ply", PlyEncoding::BinaryBigEndian},
                    PrePassCase{"PlyAscii", "scene.ply", PlyEncoding::Ascii},
                    PrePassCase{"Xyz", "scene.xyz", PlyEncoding::Ascii},
                    PrePassCase{"LasWithoutHeaderBounds", "scene.las", PlyEncoding::Ascii}),
    [](const testing::TestParamInfo<PrePassCase>& info) { return std::string(info.param.name); });

PipelineOptions smallOptions() {
    PipelineOptions options;
    options.build.maxLevel = 6;
    options.sortChunks = 8;
    return options;
}

TEST(BuildPipelinePrePass, CancelDuringThePrePassKeepsThePreviousCloudAndHierarchy) {
    test::TempDir dir;
    const std::string path =
        writeCase(dir, {"PlyAscii", "scene.ply", PlyEncoding::Ascii}); // a slow, long scan
    const std::uint64_t fileBytes = std::filesystem::file_size(path);
    BuildPipeline pipeline;
    ASSERT_TRUE(pipeline.runGeneratedScene(20'000, 3, smallOptions()).stats.complete);
    const auto hierarchyBefore = pipeline.hierarchy();
    const auto cloudBefore = pipeline.sortedCloud();

    std::uint64_t lastScanned = 0;
    std::size_t reports = 0, reportsAfterCancel = 0;
    bool cancelled = false;
    pipeline.setPrePassObserver([&](std::uint64_t scanned, std::uint64_t) {
        lastScanned = scanned;
        reportsAfterCancel += cancelled ? 1 : 0;
        if (++reports == 2) { // after the first block
            // What the builder service's Cancel does, from any thread.
            pipeline.cancel();
            cancelled = true;
            // progress() shows the scan while it runs.
            const PipelineProgress progress = pipeline.progress();
            EXPECT_EQ(progress.phase, BuildPhase::Opening);
            EXPECT_EQ(progress.bytesScanned, scanned);
            EXPECT_EQ(progress.bytesToScan, fileBytes);
        }
    });
    const PipelineResult result = pipeline.run(path, smallOptions());
    EXPECT_TRUE(result.cancelled);
    EXPECT_EQ(reportsAfterCancel, 0u) << "the scan went on after the cancel";
    EXPECT_LT(lastScanned, fileBytes);
    const PipelineProgress progress = pipeline.progress();
    EXPECT_EQ(progress.phase, BuildPhase::Cancelled);
    EXPECT_LT(progress.bytesScanned, progress.bytesToScan);
    EXPECT_EQ(pipeline.hierarchy(), hierarchyBefore);
    EXPECT_EQ(pipeline.sortedCloud(), cloudBefore);
    EXPECT_EQ(pipeline.source()->kind, PipelineKind::GeneratedScene);
    EXPECT_EQ(pipeline.sourceReads(), 1u) << "the cancelled file was never read into the sorter";
    EXPECT_TRUE(pipeline.hasCompleteCloud());

    // Once reset, the same file opens completely, the scan reaching its end.
    pipeline.resetCancel();
    const PipelineResult full = pipeline.run(path, smallOptions());
    EXPECT_TRUE(full.stats.complete);
    EXPECT_EQ(pipeline.progress().bytesScanned, fileBytes);
    EXPECT_NE(pipeline.hierarchy(), hierarchyBefore);
}

} // namespace
} // namespace omicron
