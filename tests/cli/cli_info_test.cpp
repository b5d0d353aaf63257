// omicron-cli as a user runs it: help, exit codes, info on every shared scan, generate.
#include "run_process.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <filesystem>
#include <gtest/gtest.h>

namespace omicron {
namespace {

using test::runProcess;

TEST(CliBasics, HelpListsEveryCommandAndExitsZero) {
    const auto result = runProcess(OMICRON_CLI_PATH, {"--help"});
    EXPECT_EQ(result.exitCode, 0);
    for (const char* command : {"info", "generate", "sort", "export"}) {
        EXPECT_NE(result.out.find(command), std::string::npos) << command;
        const auto help = runProcess(OMICRON_CLI_PATH, {command, "--help"});
        EXPECT_EQ(help.exitCode, 0) << command;
        EXPECT_NE(help.out.find("usage: omicron-cli"), std::string::npos) << command;
    }
}

TEST(CliBasics, UsageErrorsExitTwoWithAReason) {
    const auto noCommand = runProcess(OMICRON_CLI_PATH, {});
    EXPECT_EQ(noCommand.exitCode, 2);
    const auto unknown = runProcess(OMICRON_CLI_PATH, {"frobnicate"});
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_NE(unknown.err.find("frobnicate"), std::string::npos);
    const auto badOption = runProcess(OMICRON_CLI_PATH, {"info", "x.ply", "--fast"});
    EXPECT_EQ(badOption.exitCode, 2);
    EXPECT_NE(badOption.err.find("--fast"), std::string::npos) << badOption.err;
    const auto badNumber = runProcess(OMICRON_CLI_PATH, {"generate", "--points", "many", "o.ply"});
    EXPECT_EQ(badNumber.exitCode, 2);
    const auto missingArgument = runProcess(OMICRON_CLI_PATH, {"info"});
    EXPECT_EQ(missingArgument.exitCode, 2);
}

TEST(CliBasics, InputErrorsExitOneAndNameTheFile) {
    test::TempDir dir;
    const std::string missing = dir.file("missing.ply");
    const auto result = runProcess(OMICRON_CLI_PATH, {"info", missing});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_NE(result.err.find(missing), std::string::npos) << result.err;
    const auto directory = runProcess(OMICRON_CLI_PATH, {"info", dir.path().string()});
    EXPECT_EQ(directory.exitCode, 1);
    EXPECT_NE(directory.err.find("directory"), std::string::npos) << directory.err;
    const std::string laz = dir.file("scan.laz");
    test::writeText(laz, "not really compressed");
    const auto lazResult = runProcess(OMICRON_CLI_PATH, {"info", laz});
    EXPECT_EQ(lazResult.exitCode, 1);
    EXPECT_NE(lazResult.err.find("LAZ"), std::string::npos) << lazResult.err;
}

TEST(CliGenerate, GeneratedCloudReadsBackWithItsExactCount) {
    test::TempDir dir;
    const std::string out = dir.file("scene.ply");
    const auto generated =
        runProcess(OMICRON_CLI_PATH, {"generate", "--points", "20000", "--seed", "3", out});
    ASSERT_EQ(generated.exitCode, 0) << generated.err;
    const auto info = runProcess(OMICRON_CLI_PATH, {"info", out, "--json"});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    EXPECT_NE(info.out.find("\"points_read\":20000"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("\"attributes\":[\"normal\",\"color\"]"), std::string::npos)
        << info.out;
    // Deterministic: the same arguments write the same bytes.
    const std::string again = dir.file("again.ply");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"generate", "--points", "20000", "--seed", "3", again})
                  .exitCode,
              0);
    EXPECT_EQ(test::readBytes(out), test::readBytes(again));
}

struct SharedFileCount {
    const char* name;
    const char* points;
};

class CliInfoSharedData : public ::testing::TestWithParam<SharedFileCount> {};

TEST_P(CliInfoSharedData, PrintsTheRightCount) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam().name);
    const auto text = runProcess(OMICRON_CLI_PATH, {"info", path});
    ASSERT_EQ(text.exitCode, 0) << text.err;
    const std::string expected = std::string(GetParam().points) + " declared, " +
                                 GetParam().points + " read, 0 non-finite skipped";
    EXPECT_NE(text.out.find(expected), std::string::npos) << text.out;
    const auto json = runProcess(OMICRON_CLI_PATH, {"info", path, "--json"});
    ASSERT_EQ(json.exitCode, 0) << json.err;
    EXPECT_NE(json.out.find(std::string("\"points_read\":") + GetParam().points), std::string::npos)
        << json.out;
}

INSTANTIATE_TEST_SUITE_P(Files, CliInfoSharedData,
                         ::testing::Values(SharedFileCount{"bunny.ply", "35947"},
                                           SharedFileCount{"autzen_trim.ply", "110000"},
                                           SharedFileCount{"autzen_trim.las", "110000"},
                                           SharedFileCount{"lion.ply", "341989"},
                                           SharedFileCount{"sorvilier.ply", "498868"},
                                           SharedFileCount{"indoor.ply", "808042"},
                                           SharedFileCount{"dragon.ply", "437645"},
                                           SharedFileCount{"autzen_south.ply", "4844261"},
                                           SharedFileCount{"laz/autzen_trim.laz", "110000"},
                                           SharedFileCount{"laz/simple.laz", "1065"},
                                           SharedFileCount{"laz/1.2-with-color.copc.laz", "1065"},
                                           SharedFileCount{"laz/terrascan_fmt8.laz", "697721"}),
                         [](const auto& info) { return test::fileParamName(info.param.name); });

TEST(CliInfo, UnderstandsSortedStreams) {
    OMICRON_REQUIRE_SHARED_FILE(input, "autzen_trim.las");
    test::TempDir dir;
    const std::string oms = dir.file("s.oms");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", input, oms}).exitCode, 0);
    const auto info = runProcess(OMICRON_CLI_PATH, {"info", oms, "--json"});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    EXPECT_NE(info.out.find("\"format\":\"OMS sorted stream\""), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("\"points_read\":110000"), std::string::npos) << info.out;
    // Bounds recovered from the sorted points match the LAS header within float precision.
    EXPECT_NE(info.out.find("\"min\":[636001.7"), std::string::npos) << info.out;
}

// The class counts are those of the uncompressed twin decoded by another LAZ implementation
// (counted from its raw records by LasAttributes.StatisticsCountTheClassesOfTheFile).
TEST(CliInfo, ListsEveryLasAttributeWithItsRangeAndTheClasses) {
    OMICRON_REQUIRE_SHARED_FILE(path, "laz/terrascan_fmt8.laz");
    const auto text = runProcess(OMICRON_CLI_PATH, {"info", path});
    ASSERT_EQ(text.exitCode, 0) << text.err;
    for (const char* line :
         {"classification, classification flags, return number, number of returns, scan angle, "
          "user data, point source id, scanner channel, scan direction, edge of flight line, "
          "gps time, nir, extra bytes (3)",
          "  return number          1 .. 6", "  point source id        47 .. 47",
          "  extra bytes: Deviation (uint16): Pulse shape deviation",
          "  extra bytes: confidence (uint8): confidence values",
          "coordinates: PROJCRS[\"RGF93 / Lambert-93\"",
          "  class   2 Ground                   683023 points",
          "  class  65 User 65                  10 points"}) {
        EXPECT_NE(text.out.find(line), std::string::npos) << line << "\n" << text.out;
    }
    const auto json = runProcess(OMICRON_CLI_PATH, {"info", path, "--json"});
    ASSERT_EQ(json.exitCode, 0) << json.err;
    EXPECT_NE(json.out.find("\"classes\":{\"1\":3262,\"2\":683023,\"3\":960,\"4\":873,"
                            "\"5\":9003,\"6\":590,\"65\":10}"),
              std::string::npos)
        << json.out;
    EXPECT_NE(json.out.find("\"return number\":[1,6]"), std::string::npos) << json.out;
}

// A LAZ file with wave packets (point format 5; tests/data, made by the LAZ test encoder): its
// points are read, and the user is told the waveforms are not.
TEST(CliInfo, ReadsLazWithWavePacketsAndSaysWaveformsAreIgnored) {
    const std::string path = test::repoDataFile("laz/waveform-format5.laz");
    const auto text = runProcess(OMICRON_CLI_PATH, {"info", path});
    ASSERT_EQ(text.exitCode, 0) << text.err;
    for (const char* line : {"LAS 1.4, point format 5, 63-byte records, waveform packets ignored",
                             "(POINT10 v2, GPSTIME11 v2, RGB12 v2, WAVEPACKET13 v1)",
                             "points:      250 declared, 250 read"}) {
        EXPECT_NE(text.out.find(line), std::string::npos) << line << "\n" << text.out;
    }
}

} // namespace
} // namespace omicron
