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
#include <glm/gtx/component_wise.hpp>
#include <gtest/gtest.h>
#include <limits>
#include <span>
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

// The pre-pass's preview sample is the file's own points at a constant stride, in file order,
// about kPrePassSamplePoints of them (all of a smaller file), delivered as the scan advances.
TEST_P(PrePass, SamplesEveryStrideThPointForTheFirstPixels) {
    test::TempDir dir;
    const std::string path = writeCase(dir, GetParam());
    std::vector<glm::dvec3> sampled;
    std::size_t deliveries = 0;
    OpenOptions options;
    options.onPrePassPoints = [&](std::span<const glm::dvec3> points) {
        sampled.insert(sampled.end(), points.begin(), points.end());
        ++deliveries;
    };
    const LoadedCloud cloud = loadPointCloud(path, options);
    const std::size_t n = cloud.points.size();
    ASSERT_GT(sampled.size(), 1u);
    EXPECT_GT(deliveries, 1u) << "delivered as the scan advances, not once at the end";
    const double tolerance = 1e-5 * cloud.info.cube.edge;
    const auto source = [&](std::size_t i) {
        return cloud.info.cube.toSource(cloud.points.positions[i]);
    };
    const auto near = [&](const glm::dvec3& a, const glm::dvec3& b) {
        return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::dvec3(tolerance)));
    };
    std::size_t stride = 1;
    while (stride < n && !near(sampled[1], source(stride))) {
        ++stride;
    }
    ASSERT_LT(stride, n) << "the second sample is no point of the file";
    EXPECT_EQ(sampled.size(), (n + stride - 1) / stride);
    EXPECT_LE(sampled.size(), 2 * kPrePassSamplePoints);
    std::size_t misplaced = 0;
    for (std::size_t j = 0; j < sampled.size() && j * stride < n; ++j) {
        misplaced += near(sampled[j], source(j * stride)) ? 0 : 1;
    }
    EXPECT_EQ(misplaced, 0u);
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

// While the bounds are scanned, preview() is the scan's sample in a provisional unit cube.
TEST(BuildPipelinePrePass, PreviewDuringThePrePassIsProvisional) {
    test::TempDir dir;
    const std::string path = writeCase(dir, {"PlyAscii", "scene.ply", PlyEncoding::Ascii});
    BuildPipeline pipeline;
    PreviewSample during;
    std::size_t reports = 0;
    pipeline.setPrePassObserver([&](std::uint64_t, std::uint64_t) {
        if (++reports == 3) {
            during = pipeline.preview();
        }
    });
    ASSERT_TRUE(pipeline.run(path, smallOptions()).stats.complete);
    EXPECT_TRUE(during.provisional);
    ASSERT_FALSE(during.positions.empty());
    EXPECT_EQ(during.pointsSeen, during.positions.size());
    glm::vec3 low(1.0f), high(0.0f);
    for (const glm::vec3& p : during.positions) {
        low = glm::min(low, p);
        high = glm::max(high, p);
    }
    EXPECT_GE(glm::compMin(low), 0.0f);
    EXPECT_LE(glm::compMax(high), 1.0f);
    EXPECT_FLOAT_EQ(glm::compMax(high - low), 1.0f) << "framed by the sample's own bounds";
    EXPECT_TRUE(pipeline.preview().positions.empty()) << "nothing left after the run";
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
