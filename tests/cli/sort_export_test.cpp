// omicron-cli sort and export, run as real processes on every shared scan: the exported PLY
// holds the input's points in non-decreasing Morton order of the input's cube.
#include "formats/oms_reader.hpp"
#include "io/point_reader.hpp"
#include "run_process.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace omicron {
namespace {

using test::runProcess;

std::array<std::uint32_t, 3> bitsOf(const glm::vec3& p) {
    std::array<std::uint32_t, 3> bits;
    std::memcpy(bits.data(), &p, sizeof bits);
    return bits;
}

class CliSortExport : public ::testing::TestWithParam<const char*> {};

TEST_P(CliSortExport, ExportedPointsAreTheInputInMortonOrder) {
    OMICRON_REQUIRE_SHARED_FILE(input, GetParam());
    test::TempDir dir;
    const std::string oms = dir.file("sorted.oms");
    const std::string ply = dir.file("exported.ply");

    const auto sorted = runProcess(OMICRON_CLI_PATH, {"sort", input, oms, "--chunks", "16"});
    ASSERT_EQ(sorted.exitCode, 0) << sorted.err;
    EXPECT_NE(sorted.err.find("sorted and written"), std::string::npos) << "no progress line";
    const auto exported = runProcess(OMICRON_CLI_PATH, {"export", oms, ply});
    ASSERT_EQ(exported.exitCode, 0) << exported.err;

    // The .oms holds exactly the reader's unit-cube positions, in Morton order.
    const LoadedCloud original = loadPointCloud(input);
    OmsReader reader(oms);
    reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
    const auto cloud = reader.cloud();
    ASSERT_EQ(cloud->sortedEnd(), original.points.size());
    EXPECT_EQ(cloud->cube(), original.info.cube);
    std::vector<std::array<std::uint32_t, 3>> in, out;
    for (std::size_t i = 0; i < cloud->sortedEnd(); ++i) {
        const glm::vec3& p = cloud->positions()[i];
        if (i > 0) {
            const glm::vec3& q = cloud->positions()[i - 1];
            ASSERT_LE(morton::encodeUnit(q.x, q.y, q.z), morton::encodeUnit(p.x, p.y, p.z))
                << "point " << i << " out of Morton order";
        }
        out.push_back(bitsOf(p));
    }
    for (const glm::vec3& p : original.points.positions) {
        in.push_back(bitsOf(p));
    }
    std::sort(in.begin(), in.end());
    std::sort(out.begin(), out.end());
    ASSERT_TRUE(in == out) << "the sorted file is not a permutation of the input";

    // The PLY holds those points in the same order, in source units (float storage).
    const LoadedCloud plyCloud = loadPointCloud(ply);
    ASSERT_EQ(plyCloud.points.size(), cloud->sortedEnd());
    const double tolerance = 1e-6 * original.info.cube.edge + 1e-4;
    for (std::size_t i = 0; i < plyCloud.points.size(); ++i) {
        const glm::dvec3 expected = cloud->cube().toSource(cloud->positions()[i]);
        const glm::dvec3 actual = plyCloud.info.cube.toSource(plyCloud.points.positions[i]);
        ASSERT_NEAR(actual.x, expected.x, tolerance) << "point " << i;
        ASSERT_NEAR(actual.y, expected.y, tolerance) << "point " << i;
        ASSERT_NEAR(actual.z, expected.z, tolerance) << "point " << i;
    }
    // PLY keeps normals, colour and intensity; the LAS fields go to a LAS export (below).
    AttributeSet plyAttributes;
    for (Attribute a : {Attribute::Normal, Attribute::Color, Attribute::Intensity}) {
        if (original.info.attributes.has(a)) {
            plyAttributes.add(a);
        }
    }
    EXPECT_EQ(plyCloud.info.attributes, plyAttributes);
}

INSTANTIATE_TEST_SUITE_P(Files, CliSortExport,
                         ::testing::Values("bunny.ply", "autzen_trim.ply", "autzen_trim.las",
                                           "lion.ply", "sorvilier.ply", "indoor.ply", "dragon.ply",
                                           "autzen_south.ply"),
                         test::FileParamName());

// A LAS file whose intensities and LAS fields are all zero (tiled from a PLY) sorts into a
// .oms that keeps them once in its header (version 2): the file is the records without them,
// `info` names them, and building from it gives the same hierarchy as building from the LAS;
// sorted or built beyond the memory budget, the same bytes. A scan whose fields vary keeps
// them in every record.
TEST(CliSort, UniformLasColumnsAreStoredOnce) {
    OMICRON_REQUIRE_SHARED_FILE(ply, "autzen_trim.ply");
    OMICRON_REQUIRE_SHARED_FILE(scan, "autzen_trim.las");
    test::TempDir dir;
    // Tiled 4 times (0.44 M points): enough for a sort beyond the smallest budget, 4 MiB.
    const std::string las = dir.file("tiled.las");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"tile", ply, las, "--copies", "4"}).exitCode, 0);
    const std::string oms = dir.file("tiled.oms");
    const auto sorted = runProcess(OMICRON_CLI_PATH, {"sort", las, oms});
    ASSERT_EQ(sorted.exitCode, 0) << sorted.err;
    const std::uint64_t points = openPointCloud(las)->info().pointCount;
    EXPECT_EQ(std::filesystem::file_size(oms), 128 + points * 15 + 24) << "position and colour";
    const auto info = runProcess(OMICRON_CLI_PATH, {"info", oms});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    EXPECT_NE(info.out.find("version 2, Morton order at depth 21, 15-byte records, uniform "
                            "intensity 0, uniform LAS record"),
              std::string::npos)
        << info.out;

    // The level table and point counts: everything `build` prints before its timings.
    const auto hierarchyOf = [](const std::string& input) {
        const auto built = runProcess(OMICRON_CLI_PATH, {"build", input});
        EXPECT_EQ(built.exitCode, 0) << built.err;
        const std::size_t from = built.out.find("points:");
        return built.out.substr(from, built.out.find("time:") - from);
    };
    EXPECT_EQ(hierarchyOf(oms), hierarchyOf(las));

    // A sort beyond its memory budget (runs on disk) finds them too: the same .oms bytes, and
    // a build beyond it saves the same .omh bytes.
    const std::string spilledOms = dir.file("spilled.oms");
    const auto spilled =
        runProcess(OMICRON_CLI_PATH, {"sort", las, spilledOms, "--memory-budget", "4M"});
    ASSERT_EQ(spilled.exitCode, 0) << spilled.err;
    EXPECT_NE(spilled.out.find("runs merged"), std::string::npos) << spilled.out;
    EXPECT_EQ(test::readBytes(spilledOms), test::readBytes(oms));
    const std::string omh = dir.file("in-memory.omh");
    const std::string spilledOmh = dir.file("spilled.omh");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"build", las, "--save", omh}).exitCode, 0);
    const auto spilledBuild =
        runProcess(OMICRON_CLI_PATH, {"build", las, "--memory-budget", "4M", "--save", spilledOmh});
    ASSERT_EQ(spilledBuild.exitCode, 0) << spilledBuild.err;
    EXPECT_NE(spilledBuild.out.find("sorted runs on disk"), std::string::npos) << spilledBuild.out;
    EXPECT_EQ(test::readBytes(spilledOmh), test::readBytes(omh));

    const std::string scanOms = dir.file("scan.oms");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", scan, scanOms}).exitCode, 0);
    const auto scanInfo = runProcess(OMICRON_CLI_PATH, {"info", scanOms});
    EXPECT_EQ(scanInfo.out.find("uniform"), std::string::npos) << scanInfo.out;
}

// A PLY that declares 10 vertices and holds none: dir/broken.ply.
std::string writeBrokenPly(const test::TempDir& dir) {
    const std::string broken = dir.file("broken.ply");
    test::writeText(broken, "ply\nformat binary_little_endian 1.0\nelement vertex 10\n"
                            "property float x\nproperty float y\nproperty float z\nend_header\n");
    return broken;
}

TEST(CliSort, BadInputFailsWithExitOneAndLeavesNoOutput) {
    test::TempDir dir;
    const std::string broken = writeBrokenPly(dir);
    const std::string oms = dir.file("out.oms");
    const auto result = runProcess(OMICRON_CLI_PATH, {"sort", broken, oms});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_NE(result.err.find(broken), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(oms));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1)
        << "a temporary file was left behind";
}

// sort, convert and export read their whole input before they write: an output that cannot
// be written is checked first and fails at once (the input here is broken too, and the error
// is the output's), leaving nothing behind.
TEST(CliSort, AnUnwritableOutputFailsBeforeTheInputIsRead) {
    test::TempDir dir;
    const std::string broken = writeBrokenPly(dir);
    const std::string missing = dir.file("no-such-folder");
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"sort", broken, missing + "/out.oms"},
          std::vector<std::string>{"convert", broken, missing + "/out.oms"},
          std::vector<std::string>{"convert", broken, missing + "/out.las"},
          std::vector<std::string>{"export", broken, missing + "/out.ply"}}) {
        const auto result = runProcess(OMICRON_CLI_PATH, args);
        EXPECT_EQ(result.exitCode, 1) << args[0] << " " << args[2];
        EXPECT_NE(result.err.find(args[2] + ": cannot create a temporary file"), std::string::npos)
            << result.err;
        EXPECT_EQ(result.err.find(broken), std::string::npos) << result.err;
    }
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1)
        << "something was left behind";
}

TEST(CliSort, UsageErrorsExitTwo) {
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", "only-one-argument"}).exitCode, 2);
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", "a.ply", "b.oms", "--chunks", "0"}).exitCode,
              2);
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", "a.ply", "b.oms", "--chunks", "257"}).exitCode,
              2);
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"export", "a.oms"}).exitCode, 2);
}

TEST(CliExport, CorruptedSortedFileFailsWithExitOne) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string oms = dir.file("sorted.oms");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", input, oms}).exitCode, 0);
    auto bytes = test::readBytes(oms);
    bytes[bytes.size() / 2] ^= 0x5a;
    test::writeBytes(oms, bytes);
    const std::string ply = dir.file("out.ply");
    const auto result = runProcess(OMICRON_CLI_PATH, {"export", oms, ply});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_NE(result.err.find(oms), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(ply));
}

} // namespace
} // namespace omicron
