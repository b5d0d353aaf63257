// omicron-cli build --save / info on .omh files, driven as a user would: the per-level counts
// agree, --verify catches damage, and a save killed half-way leaves the old file usable.
#include "run_process.hpp"
#include "std_regex.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>
#include <thread>

namespace omicron {
namespace {

using test::runProcess;

// The "levels":[...] array of a JSON report, verbatim.
std::string levelsArray(const std::string& json) {
    const std::regex levels(R"re("levels":\[[^\]]*\])re");
    std::smatch match;
    return std::regex_search(json, match, levels) ? match.str() : std::string();
}

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

TEST(CliOmh, InfoPrintsTheSameLevelsAsBuildJson) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string saved = dir.file("a.omh");
    for (const char* collapse : {"off", "paper"}) {
        SCOPED_TRACE(collapse);
        const auto build = runProcess(OMICRON_CLI_PATH, {"build", input, "--depth", "6",
                                                         "--collapse", collapse, "--save", saved,
                                                         "--json"});
        ASSERT_EQ(build.exitCode, 0) << build.err;
        EXPECT_NE(build.out.find("\"saved\":"), std::string::npos);
        const auto info = runProcess(OMICRON_CLI_PATH, {"info", saved, "--json", "--verify"});
        ASSERT_EQ(info.exitCode, 0) << info.err;
        const std::string levels = levelsArray(build.out);
        ASSERT_NE(levels, "");
        EXPECT_EQ(levelsArray(info.out), levels);
        EXPECT_NE(info.out.find("\"verified\":true"), std::string::npos);
        EXPECT_NE(info.out.find(std::string("\"collapse\":\"") + collapse + "\""),
                  std::string::npos);
    }
    const auto text = runProcess(OMICRON_CLI_PATH, {"info", saved});
    ASSERT_EQ(text.exitCode, 0) << text.err;
    EXPECT_NE(text.out.find("OMH hierarchy"), std::string::npos);
}

TEST(CliOmh, VerifyExitsOneOnADamagedSectionAndNamesIt) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string saved = dir.file("a.omh");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"build", input, "--depth", "5", "--save", saved})
                  .exitCode,
              0);
    std::vector<std::uint8_t> bytes = test::readBytes(saved);
    bytes[4096 + 100] ^= 0x10; // in the deepest level's positions (version 4: its columns first)
    test::writeBytes(saved, bytes);
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"info", saved}).exitCode, 0)
        << "without --verify only the header, level table and footer are read";
    const auto verify = runProcess(OMICRON_CLI_PATH, {"info", saved, "--verify"});
    EXPECT_EQ(verify.exitCode, 1);
    EXPECT_NE(verify.err.find(saved), std::string::npos) << verify.err;
    EXPECT_NE(verify.err.find("columns of level 5"), std::string::npos) << verify.err;
}

TEST(CliOmh, SaveVersionsTwoToFourDescribeTheSameLevels) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string v4 = dir.file("v4.omh"), v3 = dir.file("v3.omh"), v2 = dir.file("v2.omh");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"build", input, "--depth", "4", "--save", v4}).exitCode,
              0);
    for (const auto& [path, version] : {std::pair{v3, "3"}, std::pair{v2, "2"}}) {
        const auto build = runProcess(OMICRON_CLI_PATH, {"build", input, "--depth", "4", "--save",
                                                         path, "--save-version", version});
        ASSERT_EQ(build.exitCode, 0) << build.err;
    }
    const auto infoV4 = runProcess(OMICRON_CLI_PATH, {"info", v4, "--json", "--verify"});
    const auto infoV3 = runProcess(OMICRON_CLI_PATH, {"info", v3, "--json", "--verify"});
    const auto infoV2 = runProcess(OMICRON_CLI_PATH, {"info", v2, "--json", "--verify"});
    ASSERT_EQ(infoV4.exitCode, 0) << infoV4.err;
    ASSERT_EQ(infoV3.exitCode, 0) << infoV3.err;
    ASSERT_EQ(infoV2.exitCode, 0) << infoV2.err;
    EXPECT_NE(infoV4.out.find("\"version\":4"), std::string::npos) << infoV4.out;
    EXPECT_NE(infoV3.out.find("\"version\":3"), std::string::npos) << infoV3.out;
    EXPECT_NE(infoV2.out.find("\"version\":2"), std::string::npos) << infoV2.out;
    EXPECT_EQ(levelsArray(infoV2.out), levelsArray(infoV3.out));
    EXPECT_EQ(levelsArray(infoV4.out), levelsArray(infoV3.out));
    // Version 4 holds the same bytes as version 3 but for the deepest level's columns: the
    // padding to 4096-byte boundaries after the level table, after each column and after the
    // last one (bunny: positions and normals, no colour).
    EXPECT_GT(std::filesystem::file_size(v4), std::filesystem::file_size(v3));
    EXPECT_LT(std::filesystem::file_size(v4), std::filesystem::file_size(v3) + 3 * 4096);
    const std::regex stored(R"re("points_stored":(\d+),"splat_attributes_stored":(\d+))re");
    std::smatch a, b;
    ASSERT_TRUE(std::regex_search(infoV2.out, a, stored)) << infoV2.out;
    ASSERT_TRUE(std::regex_search(infoV3.out, b, stored)) << infoV3.out;
    EXPECT_EQ(a[1], a[2]) << "version 2 stores every point's attributes";
    EXPECT_LT(std::stoull(b[2]), std::stoull(b[1])) << "version 3 only the sparse nodes'";
    // Bunny has normals: a version 2 record is 2 bytes longer for each estimated point.
    EXPECT_EQ(std::filesystem::file_size(v2) - std::filesystem::file_size(v3),
              2 * (std::stoull(b[1]) - std::stoull(b[2])) -
                  5 * 8) // 5 level entries, 8 bytes shorter
        << infoV2.out << infoV3.out;
    for (const char* bad : {"1", "5", "three"}) {
        const auto refused = runProcess(
            OMICRON_CLI_PATH, {"build", input, "--save", dir.file("x.omh"), "--save-version", bad});
        EXPECT_EQ(refused.exitCode, 2) << bad;
        EXPECT_NE(refused.err.find("--save-version"), std::string::npos) << refused.err;
        EXPECT_FALSE(std::filesystem::exists(dir.file("x.omh")));
    }
}

TEST(CliOmh, SaveIntoAMissingFolderFailsNamingTheFile) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string target = dir.file("missing/a.omh");
    const auto build = runProcess(OMICRON_CLI_PATH, {"build", input, "--save", target});
    EXPECT_EQ(build.exitCode, 1);
    EXPECT_NE(build.err.find(target), std::string::npos) << build.err;
}

TEST(CliOmh, ASaveKilledHalfWayLeavesThePreviousFileIntact) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string saved = dir.file("a.omh");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"build", input, "--depth", "4", "--save", saved})
                  .exitCode,
              0);
    const std::vector<std::uint8_t> before = test::readBytes(saved);

    const std::string errPath = dir.file("stderr");
    test::RunningProcess child(OMICRON_CLI_PATH, {"build", input, "--depth", "7", "--save", saved},
                               {"OMICRON_TEST_PAUSE_SAVE_AFTER_LEVEL=5"}, errPath);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (slurp(errPath).find("save paused") == std::string::npos) {
        ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the save never paused";
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    // The paused save has its temporary file open beside the target (with its stderr), and
    // the temporary has no name: killed, the process leaves nothing behind.
    const auto namesInDir = [&] {
        std::vector<std::string> names;
        for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
            names.push_back(entry.path().filename().string());
        }
        std::sort(names.begin(), names.end());
        return names;
    };
    EXPECT_EQ(test::openFilesIn(child.pid(), dir.path()).size(), 2u);
    EXPECT_EQ(namesInDir(), (std::vector<std::string>{"a.omh", "stderr"}));
    child.kill();

    EXPECT_EQ(namesInDir(), (std::vector<std::string>{"a.omh", "stderr"}));
    EXPECT_EQ(test::readBytes(saved), before);
    const auto info = runProcess(OMICRON_CLI_PATH, {"info", saved, "--verify", "--json"});
    EXPECT_EQ(info.exitCode, 0) << info.err;
    EXPECT_NE(info.out.find("\"depth\":4"), std::string::npos);
}

TEST(CliOmh, VerifyOnANonOmhFileIsAUsageError) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"info", input, "--verify"}).exitCode, 2);
}

} // namespace
} // namespace omicron

namespace omicron {
namespace {

TEST(CliConvert, EveryOutputFormatReadsBackWithTheSamePointCount) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    for (const char* name : {"b.las", "b.xyz", "b.oms", "b.ply"}) {
        SCOPED_TRACE(name);
        const std::string out = dir.file(name);
        const auto convert = test::runProcess(OMICRON_CLI_PATH, {"convert", input, out});
        ASSERT_EQ(convert.exitCode, 0) << convert.err;
        const auto info = test::runProcess(OMICRON_CLI_PATH, {"info", out, "--json"});
        ASSERT_EQ(info.exitCode, 0) << info.err;
        EXPECT_NE(info.out.find("\"points_read\":35947"), std::string::npos) << info.out;
    }
    EXPECT_EQ(test::runProcess(OMICRON_CLI_PATH, {"convert", input, dir.file("b.doc")}).exitCode,
              2);
}

TEST(CliExportPotree, WritesTheThreeFiles) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string saved = dir.file("a.omh");
    ASSERT_EQ(test::runProcess(OMICRON_CLI_PATH, {"build", input, "--save", saved}).exitCode, 0);
    const auto exported =
        test::runProcess(OMICRON_CLI_PATH, {"export-potree", saved, dir.file("potree")});
    ASSERT_EQ(exported.exitCode, 0) << exported.err;
    for (const char* file : {"metadata.json", "hierarchy.bin", "octree.bin"}) {
        EXPECT_GT(std::filesystem::file_size(dir.path() / "potree" / file), 0u) << file;
    }
    const auto missing =
        test::runProcess(OMICRON_CLI_PATH, {"export-potree", dir.file("none.omh"), dir.file("p")});
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_NE(missing.err.find("none.omh"), std::string::npos);
}

} // namespace
} // namespace omicron
