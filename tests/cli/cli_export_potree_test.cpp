// omicron-cli export-potree driven as a user would: straight from any cloud, a sorted stream or
// a saved hierarchy; every input point once (the counts it prints and metadata.json's); clear
// errors naming the file; Ctrl+C half-way leaves neither the folder nor a temporary one.
#include "run_process.hpp"
#include "std_regex.hpp"
#include "test_files.hpp"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <gtest/gtest.h>
#include <memory>
#include <thread>

namespace omicron {
namespace {

using test::runProcess;

std::uint64_t jsonCount(const std::string& json, const std::string& key) {
    std::smatch match;
    const bool found = std::regex_search(json, match, std::regex("\"" + key + R"(\":(\d+))"));
    EXPECT_TRUE(found) << key << " in " << json;
    return found ? std::stoull(match[1]) : 0;
}

std::uint64_t metadataPoints(const std::string& folder) {
    const auto bytes = test::readBytes(folder + "/metadata.json");
    const std::string json(bytes.begin(), bytes.end());
    std::smatch match;
    return std::regex_search(json, match, std::regex(R"re("points": (\d+))re"))
               ? std::stoull(match[1])
               : 0;
}

// Every shared scan, PLY and LAS, straight to Potree: as many points as the input.
class CliExportPotreeShared : public testing::TestWithParam<std::string> {};

TEST_P(CliExportPotreeShared, StoresEveryInputPointOnce) {
    OMICRON_REQUIRE_SHARED_FILE(input, GetParam());
    test::TempDir dir;
    const auto info = runProcess(OMICRON_CLI_PATH, {"info", input, "--json"});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const std::uint64_t inputPoints = jsonCount(info.out, "points_read");
    const std::string folder = dir.file("potree");
    const auto exported = runProcess(OMICRON_CLI_PATH, {"export-potree", input, folder, "--json"});
    ASSERT_EQ(exported.exitCode, 0) << exported.err;
    EXPECT_EQ(jsonCount(exported.out, "points"), inputPoints);
    EXPECT_EQ(jsonCount(exported.out, "input_points"), inputPoints);
    EXPECT_EQ(jsonCount(exported.out, "dropped_points"), 0u);
    EXPECT_EQ(metadataPoints(folder), inputPoints);
}

INSTANTIATE_TEST_SUITE_P(SharedScans, CliExportPotreeShared,
                         testing::Values("bunny.ply", "dragon.ply", "lion.ply", "sorvilier.ply",
                                         "indoor.ply", "autzen_trim.ply", "autzen_trim.las",
                                         "autzen_south.ply"),
                         test::FileParamName{});

TEST(CliExportPotree, SortedStreamSavedHierarchyAndPaperCollapse) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"sort", input, dir.file("a.oms")}).exitCode, 0);
    const auto fromOms = runProcess(
        OMICRON_CLI_PATH, {"export-potree", dir.file("a.oms"), dir.file("oms"), "--json"});
    ASSERT_EQ(fromOms.exitCode, 0) << fromOms.err;
    EXPECT_EQ(jsonCount(fromOms.out, "points"), 35947u);

    // A paper collapse drops points: the output says how many, and the counts add up.
    const auto build =
        runProcess(OMICRON_CLI_PATH, {"build", input, "--depth", "8", "--collapse", "paper",
                                      "--save", dir.file("a.omh"), "--json"});
    ASSERT_EQ(build.exitCode, 0) << build.err;
    const std::uint64_t dropped = jsonCount(build.out, "dropped_points");
    EXPECT_GT(dropped, 0u);
    const auto fromOmh = runProcess(
        OMICRON_CLI_PATH, {"export-potree", dir.file("a.omh"), dir.file("omh"), "--json"});
    ASSERT_EQ(fromOmh.exitCode, 0) << fromOmh.err;
    EXPECT_EQ(jsonCount(fromOmh.out, "dropped_points"), dropped);
    EXPECT_EQ(jsonCount(fromOmh.out, "points") + dropped, 35947u);
    const auto text =
        runProcess(OMICRON_CLI_PATH, {"export-potree", dir.file("a.omh"), dir.file("omh-text")});
    ASSERT_EQ(text.exitCode, 0) << text.err;
    EXPECT_NE(text.out.find(std::to_string(dropped) + " dropped by leaf collapse"),
              std::string::npos)
        << text.out;

    // The same build straight from the cloud gives the same count.
    const auto direct =
        runProcess(OMICRON_CLI_PATH, {"export-potree", input, dir.file("direct"), "--depth", "8",
                                      "--collapse", "paper", "--json"});
    ASSERT_EQ(direct.exitCode, 0) << direct.err;
    EXPECT_EQ(jsonCount(direct.out, "points"), jsonCount(fromOmh.out, "points"));
}

TEST(CliExportPotree, ErrorsNameTheFileAndWhatIsWrong) {
    test::TempDir dir;
    const auto missing =
        runProcess(OMICRON_CLI_PATH, {"export-potree", dir.file("none.ply"), dir.file("p")});
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_NE(missing.err.find("none.ply"), std::string::npos) << missing.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("p")));

    test::writeText(dir.file("bad.ply"), "ply\nformat ascii 1.0\nelement vertex 2\nproperty "
                                         "float x\nend_header\n1\n");
    const auto bad =
        runProcess(OMICRON_CLI_PATH, {"export-potree", dir.file("bad.ply"), dir.file("p")});
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("bad.ply"), std::string::npos) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("p")));

    const auto usage = runProcess(OMICRON_CLI_PATH, {"export-potree", dir.file("bad.ply")});
    EXPECT_EQ(usage.exitCode, 2);

    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"build", input, "--save", dir.file("a.omh")}).exitCode,
              0);
    const auto depthOnSaved = runProcess(
        OMICRON_CLI_PATH, {"export-potree", dir.file("a.omh"), dir.file("p"), "--depth", "5"});
    EXPECT_EQ(depthOnSaved.exitCode, 2);
    EXPECT_NE(depthOnSaved.err.find("a.omh"), std::string::npos) << depthOnSaved.err;

    std::filesystem::create_directories(dir.file("mine"));
    test::writeText(dir.file("mine/notes.txt"), "keep");
    const auto occupied = runProcess(OMICRON_CLI_PATH, {"export-potree", input, dir.file("mine")});
    EXPECT_EQ(occupied.exitCode, 1);
    EXPECT_NE(occupied.err.find("notes.txt"), std::string::npos) << occupied.err;
    EXPECT_TRUE(std::filesystem::exists(dir.file("mine/notes.txt")));
}

// The target folder is checked before the input is read: one that may not be replaced fails
// at once rather than after the build (the input here is damaged, and the error is the
// folder's), and the folder and its parent are as they were.
TEST(CliExportPotree, AFolderThatMayNotBeReplacedFailsBeforeTheInputIsRead) {
    test::TempDir dir;
    const std::string bad = dir.file("bad.ply");
    test::writeText(bad,
                    "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n");
    std::filesystem::create_directories(dir.file("mine"));
    test::writeText(dir.file("mine/notes.txt"), "keep");
    const auto occupied = runProcess(OMICRON_CLI_PATH, {"export-potree", bad, dir.file("mine")});
    EXPECT_EQ(occupied.exitCode, 1);
    EXPECT_NE(occupied.err.find("it holds 'notes.txt'"), std::string::npos) << occupied.err;
    EXPECT_EQ(occupied.err.find("bad.ply"), std::string::npos) << occupied.err;
    EXPECT_EQ(test::readBytes(dir.file("mine/notes.txt")).size(), 4u);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator()),
              2)
        << "bad.ply and mine only";
}

// What an export run with OMICRON_TEST_PAUSE_POTREE_EXPORT=1 printed to `errPath` once it
// paused (the first node written to the temporary folder), or after 60 s without a pause.
std::string waitForPause(const std::string& errPath) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    std::string err;
    while (err.find("paused") == std::string::npos && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (std::filesystem::exists(errPath)) {
            const auto bytes = test::readBytes(errPath);
            err.assign(bytes.begin(), bytes.end());
        }
    }
    return err;
}

// Ctrl+C while octree.bin is being written: exit 130, no folder, no temporary folder, and an
// export that was there before is still there, whole.
TEST(CliExportPotree, InterruptedExportLeavesNothingHalfWritten) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string folder = dir.file("potree");
    for (const bool existedBefore : {false, true}) {
        SCOPED_TRACE(existedBefore);
        if (existedBefore) {
            ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"export-potree", input, folder}).exitCode, 0);
        }
        test::RunningProcess child(OMICRON_CLI_PATH, {"export-potree", input, folder},
                                   {"OMICRON_TEST_PAUSE_POTREE_EXPORT=1"}, dir.file("err.txt"));
        const std::string err = waitForPause(dir.file("err.txt"));
        ASSERT_NE(err.find("paused"), std::string::npos) << err;
        child.signal(SIGINT);
        EXPECT_EQ(child.waitFor(std::chrono::seconds(30)), std::optional<int>(130));
        EXPECT_EQ(std::filesystem::exists(folder), existedBefore);
        if (existedBefore) {
            EXPECT_EQ(metadataPoints(folder), 35947u);
        }
        for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
            EXPECT_EQ(entry.path().filename().string().find(".potree.tmp-"), std::string::npos)
                << entry.path();
        }
    }
}

// An export killed outright (SIGKILL: no handler, no destructor) leaves its temporary folder.
// The next export to the same target removes it once its maker is gone, and never one whose
// maker still runs.
TEST(CliExportPotree, AKilledExportsFolderIsRemovedByTheNextExport) {
    OMICRON_REQUIRE_SHARED_FILE(input, "bunny.ply");
    test::TempDir dir;
    const std::string folder = dir.file("potree");
    const auto temporaries = [&] {
        std::size_t count = 0;
        for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
            count += entry.path().filename().string().starts_with(".potree.tmp-") ? 1 : 0;
        }
        return count;
    };
    const auto startPaused = [&](const std::string& errName) {
        auto child = std::make_unique<test::RunningProcess>(
            OMICRON_CLI_PATH, std::vector<std::string>{"export-potree", input, folder},
            std::vector<std::string>{"OMICRON_TEST_PAUSE_POTREE_EXPORT=1"}, dir.file(errName));
        const std::string err = waitForPause(dir.file(errName));
        EXPECT_NE(err.find("paused"), std::string::npos) << err;
        return child;
    };
    auto paused = startPaused("paused.txt");
    ASSERT_EQ(temporaries(), 1u);
    // Another export meanwhile: the paused one still runs, so its folder stays.
    ASSERT_EQ(runProcess(OMICRON_CLI_PATH, {"export-potree", input, folder}).exitCode, 0);
    EXPECT_EQ(temporaries(), 1u) << "an export removed the folder of one still running";
    paused->kill();
    EXPECT_EQ(temporaries(), 1u) << "SIGKILL runs no clean-up";
    const auto next = runProcess(OMICRON_CLI_PATH, {"export-potree", input, folder});
    ASSERT_EQ(next.exitCode, 0) << next.err;
    EXPECT_EQ(temporaries(), 0u) << "the killed export's folder outlived the next export";
    EXPECT_EQ(metadataPoints(folder), 35947u);
}

} // namespace
} // namespace omicron
