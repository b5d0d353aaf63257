// omicron-cli build --json on real scans: per-level node counts equal a brute-force octree of
// the same depth, from unsorted input (pipeline 1) and from a .oms (pipeline 2) alike.
#include "io/point_reader.hpp"
#include "points/morton.hpp"
#include "run_process.hpp"
#include "std_regex.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <filesystem>
#include <gtest/gtest.h>

namespace omicron {
namespace {

using test::runProcess;

// "levels":[{"level":0,"nodes":N,...},...] -> the node and point counts, by level.
std::vector<std::pair<std::uint64_t, std::uint64_t>> levelCounts(const std::string& json) {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> counts;
    const std::regex level(R"re(\{"level":(\d+),"nodes":(\d+),"leaves":\d+,"points":(\d+)\})re");
    for (auto it = std::sregex_iterator(json.begin(), json.end(), level);
         it != std::sregex_iterator(); ++it) {
        EXPECT_EQ(std::stoull((*it)[1]), counts.size());
        counts.emplace_back(std::stoull((*it)[2]), std::stoull((*it)[3]));
    }
    return counts;
}

// Nodes per level of the octree of depth `depth` over the file's points: the distinct cells
// of each level, counted by brute force (every point's cell, sorted, duplicates removed).
std::vector<std::uint64_t> referenceNodes(const LoadedCloud& cloud, int depth) {
    std::vector<morton::Code> codes;
    codes.reserve(cloud.points.positions.size());
    for (const glm::vec3& p : cloud.points.positions) {
        codes.push_back(morton::encodeUnit(p.x, p.y, p.z));
    }
    std::vector<std::uint64_t> nodes;
    for (int level = 0; level <= depth; ++level) {
        std::vector<morton::Code> cells(codes.size());
        std::transform(codes.begin(), codes.end(), cells.begin(),
                       [level](morton::Code code) { return morton::codeAtLevel(code, level); });
        std::sort(cells.begin(), cells.end());
        nodes.push_back(
            static_cast<std::uint64_t>(std::unique(cells.begin(), cells.end()) - cells.begin()));
    }
    return nodes;
}

class CliBuildSharedData : public ::testing::TestWithParam<const char*> {};

TEST_P(CliBuildSharedData, LevelsMatchABruteForceOctree) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    const int depth = 6;
    const LoadedCloud cloud = loadPointCloud(path);
    const std::vector<std::uint64_t> expected = referenceNodes(cloud, depth);

    test::TempDir dir;
    const std::string oms = dir.file("sorted.oms");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", path, oms}).exitCode, 0);
    for (const std::string& input : {path, oms}) {
        const auto result = runProcess(
            OMICRON_CLI_PATH, {"build", input, "--depth", std::to_string(depth), "--json"});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        EXPECT_NE(result.out.find("\"points_in\":" + std::to_string(cloud.points.size())),
                  std::string::npos)
            << result.out;
        EXPECT_NE(result.out.find("\"complete\":true"), std::string::npos) << result.out;
        const auto levels = levelCounts(result.out);
        ASSERT_EQ(levels.size(), expected.size()) << result.out;
        for (int level = 0; level <= depth; ++level) {
            EXPECT_EQ(levels[level].first, expected[level]) << input << " level " << level;
        }
        // Collapse off: the deepest level's leaves hold every input point.
        EXPECT_EQ(levels[depth].second, cloud.points.size());
    }
}

INSTANTIATE_TEST_SUITE_P(Files, CliBuildSharedData,
                         ::testing::Values("bunny.ply", "autzen_trim.las", "autzen_trim.ply",
                                           "lion.ply", "sorvilier.ply", "indoor.ply", "dragon.ply",
                                           "autzen_south.ply", "laz/autzen_trim.laz",
                                           "laz/terrascan_fmt8.laz",
                                           "laz/1.2-with-color.copc.laz"),
                         test::FileParamName());

TEST(CliBuild, PaperCollapseCountsDroppedPointsAndBadOptionsExitTwo) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    const auto paper = runProcess(OMICRON_CLI_PATH,
                                  {"build", path, "--collapse", "paper", "--depth", "8", "--json"});
    ASSERT_EQ(paper.exitCode, 0) << paper.err;
    const std::smatch match = [&] {
        std::smatch m;
        std::regex_search(paper.out, m, std::regex(R"("dropped_points":(\d+))"));
        return m;
    }();
    ASSERT_EQ(match.size(), 2u) << paper.out;
    EXPECT_GT(std::stoull(match[1]), 0u) << "paper collapse on the bunny drops chain leaves";
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"build", path, "--collapse", "maybe"}).exitCode, 2);
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"build", path, "--depth", "22"}).exitCode, 2);
    EXPECT_EQ(runProcess(OMICRON_CLI_PATH, {"build", path, "--ratio", "1.5"}).exitCode, 2);
}

// The save's target is checked before the input is read: a target that cannot be written
// fails at once rather than after the build (the input here is damaged, and the error is the
// target's), and nothing is left behind.
TEST(CliBuild, AnUnwritableSaveTargetFailsBeforeTheInputIsRead) {
    test::TempDir dir;
    const std::string bad = dir.file("bad.ply");
    test::writeText(bad,
                    "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n");
    const std::string target = dir.file("no-such-folder/out.omh");
    const auto unwritable = runProcess(OMICRON_CLI_PATH, {"build", bad, "--save", target});
    EXPECT_EQ(unwritable.exitCode, 1);
    EXPECT_NE(unwritable.err.find(target + ": cannot create a temporary file"), std::string::npos)
        << unwritable.err;
    EXPECT_EQ(unwritable.err.find("bad.ply"), std::string::npos) << unwritable.err;
    // With a target that can be written, the same input is what fails.
    const auto writable =
        runProcess(OMICRON_CLI_PATH, {"build", bad, "--save", dir.file("out.omh")});
    EXPECT_EQ(writable.exitCode, 1);
    EXPECT_NE(writable.err.find("bad.ply"), std::string::npos) << writable.err;
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator()),
              1)
        << "only bad.ply should be there";
}

std::uint64_t jsonCount(const std::string& json, const std::string& key) {
    std::smatch match;
    if (!std::regex_search(json, match, std::regex("\"" + key + "\":(\\d+)"))) {
        ADD_FAILURE() << "no " << key << " in " << json;
        return 0;
    }
    return std::stoull(match[1]);
}

// The JSON and the text name the page size the big arrays asked for; OMICRON_HUGE_PAGES
// forces either.
TEST(CliBuild, NamesThePageSizeItUsed) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.ply");
    for (const std::string pages : {"huge", "small"}) {
        const std::string force =
            std::string("OMICRON_HUGE_PAGES=") + (pages == "huge" ? "1" : "0");
        const auto json =
            runProcess("/usr/bin/env", {force, OMICRON_CLI_PATH, "build", path, "--json"});
        ASSERT_EQ(json.exitCode, 0) << json.err;
        EXPECT_NE(json.out.find("\"pages\":\"" + pages + "\""), std::string::npos) << json.out;
        const auto text = runProcess("/usr/bin/env", {force, OMICRON_CLI_PATH, "build", path});
        ASSERT_EQ(text.exitCode, 0) << text.err;
        EXPECT_NE(text.out.find("point store on " + pages + " pages"), std::string::npos)
            << text.out;
    }
}

// --store packed, from unsorted input and from a .oms: the same levels as exact, the cloud in
// fewer bytes, the store named in the JSON; a bad store name is a usage error.
TEST(CliBuild, PackedStoreBuildsTheSameLevelsInFewerBytes) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.ply");
    test::TempDir dir;
    const std::string oms = dir.file("sorted.oms");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", path, oms}).exitCode, 0);
    for (const std::string& input : {path, oms}) {
        const auto exact = runProcess(OMICRON_CLI_PATH, {"build", input, "--json"});
        const auto packed =
            runProcess(OMICRON_CLI_PATH, {"build", input, "--store", "packed", "--json"});
        ASSERT_EQ(exact.exitCode, 0) << exact.err;
        ASSERT_EQ(packed.exitCode, 0) << packed.err;
        EXPECT_NE(exact.out.find("\"point_storage\":\"exact\""), std::string::npos) << exact.out;
        EXPECT_NE(packed.out.find("\"point_storage\":\"packed\""), std::string::npos) << packed.out;
        EXPECT_EQ(levelCounts(packed.out), levelCounts(exact.out)) << input;
        EXPECT_LT(jsonCount(packed.out, "cloud_bytes") * 3, jsonCount(exact.out, "cloud_bytes") * 2)
            << input;
    }
    const auto bad = runProcess(OMICRON_CLI_PATH, {"build", path, "--store", "zip"});
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.err.find("--store takes exact or packed"), std::string::npos) << bad.err;
}

} // namespace
} // namespace omicron
