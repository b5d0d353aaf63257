// omicron-cli tile, as a user runs it: copies read back by our readers equal the input moved by
// whole extents, point for point in file order, for PLY and LAS output; usage mistakes; Ctrl+C
// in the middle leaves neither the output nor a temporary file.
#include "io/point_reader.hpp"
#include "run_process.hpp"
#include "test_files.hpp"

#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <cstring>
#include <gtest/gtest.h>
#include <string>
#include <thread>
#include <vector>

namespace omicron {
namespace {

using test::TempDir;

test::ProcessResult runCli(const std::vector<std::string>& args) {
    return test::runProcess(OMICRON_CLI_PATH, args);
}

// The grid the command documents: ceil(sqrt N) columns along x, rows along y, steps of the
// input's extent plus the gap.
glm::dvec3 expectedShift(std::uint64_t copy, std::uint64_t copies, const Bounds& bounds,
                         double gap) {
    const auto columns = static_cast<std::uint64_t>(std::ceil(std::sqrt(double(copies))));
    const glm::dvec3 extent = bounds.extent();
    return {double(copy % columns) * (extent.x + gap), double(copy / columns) * (extent.y + gap),
            0.0};
}

// Every output point is the input point of the same index in its copy, shifted; attributes
// carried when the output format has them.
void expectCopies(const LoadedCloud& in, const LoadedCloud& out, std::uint64_t copies, double gap,
                  double tolerance, bool normalsKept) {
    const std::size_t n = in.points.size();
    ASSERT_EQ(out.points.size(), n * copies);
    EXPECT_EQ(out.points.attributes.has(Attribute::Color),
              in.points.attributes.has(Attribute::Color));
    EXPECT_EQ(out.points.attributes.has(Attribute::Normal),
              normalsKept && in.points.attributes.has(Attribute::Normal));
    double worst = 0.0;
    std::size_t colorMismatches = 0;
    for (std::uint64_t copy = 0; copy < copies; ++copy) {
        const glm::dvec3 shift = expectedShift(copy, copies, in.info.sourceBounds, gap);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t o = copy * n + i;
            const glm::dvec3 expected = in.info.cube.toSource(in.points.positions[i]) + shift;
            const glm::dvec3 found = out.info.cube.toSource(out.points.positions[o]);
            const glm::dvec3 error = glm::abs(found - expected);
            worst = std::max({worst, error.x, error.y, error.z});
            if (in.points.attributes.has(Attribute::Color) &&
                out.points.colors[o] != in.points.colors[i]) {
                ++colorMismatches;
            }
        }
    }
    EXPECT_LE(worst, tolerance);
    EXPECT_EQ(colorMismatches, 0u);
}

TEST(CliTile, PlyCopiesAreTheInputShiftedByWholeExtents) {
    OMICRON_REQUIRE_SHARED_FILE(bunny, "bunny.ply");
    TempDir dir;
    const std::string out = dir.file("bunnies.ply");
    const auto run = runCli({"tile", bunny, out, "--copies", "5"});
    ASSERT_EQ(run.exitCode, 0) << run.err;
    EXPECT_NE(run.out.find("wrote 5 copies of 35947 points (179735 points)"), std::string::npos)
        << run.out;
    const LoadedCloud in = loadPointCloud(bunny);
    const LoadedCloud tiled = loadPointCloud(out);
    // Float coordinates against an offset: a few micrometres on the bunny's 0.2 m copies.
    expectCopies(in, tiled, 5, 0.0, 1e-5, true);
    // Five copies fill three columns and two rows; no copy lands on another.
    const glm::dvec3 extent = in.info.sourceBounds.extent();
    EXPECT_NEAR(tiled.info.sourceBounds.extent().x, 3 * extent.x, 1e-5);
    EXPECT_NEAR(tiled.info.sourceBounds.extent().y, 2 * extent.y, 1e-5);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(CliTile, LasCopiesKeepIntensityAndColourWithTheGap) {
    OMICRON_REQUIRE_SHARED_FILE(las, "autzen_trim.las");
    TempDir dir;
    const std::string out = dir.file("autzen.las");
    const auto run = runCli({"tile", las, out, "--copies", "3", "--gap", "25.5"});
    ASSERT_EQ(run.exitCode, 0) << run.err;
    const LoadedCloud in = loadPointCloud(las);
    const LoadedCloud tiled = loadPointCloud(out);
    EXPECT_EQ(tiled.info.format, CloudFormat::Las);
    // Millimetre steps: at most half a step off, plus the float positions of the unit cube.
    expectCopies(in, tiled, 3, 25.5, 0.0006 + tiled.info.cube.edge * 1e-7, false);
    ASSERT_TRUE(in.points.attributes.has(Attribute::Intensity));
    ASSERT_TRUE(tiled.points.attributes.has(Attribute::Intensity));
    for (std::size_t copy = 0; copy < 3; ++copy) {
        for (std::size_t i = 0; i < in.points.size(); i += 97) {
            ASSERT_EQ(tiled.points.intensities[copy * in.points.size() + i],
                      in.points.intensities[i]);
            // The LAS fields too (classification, returns, GPS time...), byte for byte.
            const std::size_t lasBytes = in.points.attributes.lasBytes();
            ASSERT_EQ(tiled.points.attributes.lasBytes(), lasBytes);
            ASSERT_EQ(std::memcmp(&tiled.points.las[(copy * in.points.size() + i) * lasBytes],
                                  &in.points.las[i * lasBytes], lasBytes),
                      0)
                << "point " << i << " of copy " << copy;
        }
    }
}

TEST(CliTile, NormalsAreDroppedForLasOnly) {
    OMICRON_REQUIRE_SHARED_FILE(lion, "lion.ply");
    TempDir dir;
    const LoadedCloud in = loadPointCloud(lion);
    if (!in.points.attributes.has(Attribute::Normal)) {
        GTEST_SKIP() << "lion.ply has no normals";
    }
    const auto run = runCli({"tile", lion, dir.file("lions.las"), "--copies", "2"});
    ASSERT_EQ(run.exitCode, 0) << run.err;
    const LoadedCloud tiled = loadPointCloud(dir.file("lions.las"));
    expectCopies(in, tiled, 2, 0.0, 0.0006 + tiled.info.cube.edge * 1e-7, false);
}

struct TileUsage {
    const char* name;
    std::vector<std::string> args;
    std::string reason;
};

class CliTileUsage : public testing::TestWithParam<TileUsage> {};

TEST_P(CliTileUsage, ExitsTwoWithTheReason) {
    const auto run = runCli(GetParam().args);
    EXPECT_EQ(run.exitCode, 2) << run.err;
    EXPECT_NE(run.err.find("omicron-cli: tile: " + GetParam().reason), std::string::npos)
        << run.err;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CliTileUsage,
    testing::Values(
        TileUsage{"NoCopies", {"tile", "in.ply", "out.ply"}, "--copies N is required"},
        TileUsage{"ZeroCopies",
                  {"tile", "in.ply", "out.ply", "--copies", "0"},
                  "--copies 0 is out of range (expected 1..1000000)"},
        TileUsage{"BadExtension",
                  {"tile", "in.ply", "out.xyz", "--copies", "2"},
                  "OUT must end in .ply or .las, found 'out.xyz'"},
        TileUsage{"NegativeGap",
                  {"tile", "in.ply", "out.ply", "--copies", "2", "--gap", "-1"},
                  "bad number for --gap: '-1'"},
        TileUsage{"OneFile", {"tile", "in.ply", "--copies", "2"}, "expected IN and OUT, found 1"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(CliTile, MissingInputIsAnInputErrorAndWritesNothing) {
    TempDir dir;
    const auto run = runCli({"tile", dir.file("absent.ply"), dir.file("out.ply"), "--copies", "2"});
    EXPECT_EQ(run.exitCode, 1);
    EXPECT_NE(run.err.find("absent.ply"), std::string::npos) << run.err;
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// Ctrl+C part way: exit 130, no output and no temporary file. The signal goes as soon as the
// temporary exists, long before 40 copies of 4.8 M points (2.9 GB) could be written.
TEST(CliTile, InterruptLeavesNoOutputNorTemporary) {
    OMICRON_REQUIRE_SHARED_FILE(south, "autzen_south.ply");
    TempDir dir;
    const std::string out = (dir.path() / "out" / "big.ply").string();
    std::filesystem::create_directory(dir.path() / "out");
    test::RunningProcess child(OMICRON_CLI_PATH, {"tile", south, out, "--copies", "40"}, {},
                               dir.file("stderr.txt"));
    // The temporary has no name until it is complete: it shows as the child's open file.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (test::openFilesIn(child.pid(), dir.path() / "out").empty() &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_FALSE(test::openFilesIn(child.pid(), dir.path() / "out").empty())
        << "no temporary file appeared";
    child.signal(SIGINT);
    const std::optional<int> status = child.waitFor(std::chrono::seconds(60));
    ASSERT_TRUE(status.has_value()) << "tile did not stop after SIGINT";
    const std::vector<std::uint8_t> err = test::readBytes(dir.file("stderr.txt"));
    const std::string errText(err.begin(), err.end());
    EXPECT_EQ(*status, 130) << errText;
    EXPECT_NE(errText.find("interrupted; no output was written"), std::string::npos) << errText;
    EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "out"));
}

} // namespace
} // namespace omicron
