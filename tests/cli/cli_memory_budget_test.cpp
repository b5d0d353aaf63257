// --memory-budget and --temp-dir as a user gives them: a sort, a conversion and a build under a
// budget that forces sorted runs onto disk give the same .oms bytes and the same hierarchy as
// without one, leave no run behind, and Ctrl+C in the middle leaves neither runs nor output.
#include "run_process.hpp"
#include "test_files.hpp"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <gtest/gtest.h>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace omicron {
namespace {

using test::TempDir;

test::ProcessResult runCli(const std::vector<std::string>& args) {
    return test::runProcess(OMICRON_CLI_PATH, args);
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// The "levels" array of build --json.
std::string levelsOf(const std::string& json) {
    const std::size_t begin = json.find("\"levels\"");
    const std::size_t end = json.find(']', begin);
    return begin == std::string::npos ? "" : json.substr(begin, end - begin);
}

TEST(CliMemoryBudget, SpilledSortWritesTheSameSortedStream) {
    OMICRON_REQUIRE_SHARED_FILE(lion, "lion.ply");
    TempDir dir;
    TempDir scratch;
    const auto reference = runCli({"sort", lion, dir.file("reference.oms")});
    ASSERT_EQ(reference.exitCode, 0) << reference.err;
    EXPECT_TRUE(contains(reference.out, "chunks")) << reference.out;
    const auto spilled = runCli({"sort", lion, dir.file("spilled.oms"), "--memory-budget", "4M",
                                 "--temp-dir", scratch.path().string()});
    ASSERT_EQ(spilled.exitCode, 0) << spilled.err;
    EXPECT_TRUE(contains(spilled.out, "runs merged")) << spilled.out;
    EXPECT_EQ(test::readBytes(dir.file("spilled.oms")), test::readBytes(dir.file("reference.oms")));
    EXPECT_TRUE(std::filesystem::is_empty(scratch.path()));

    const auto converted = runCli({"convert", lion, dir.file("converted.oms"), "--memory-budget",
                                   "4M", "--temp-dir", scratch.path().string()});
    ASSERT_EQ(converted.exitCode, 0) << converted.err;
    EXPECT_EQ(test::readBytes(dir.file("converted.oms")),
              test::readBytes(dir.file("reference.oms")));
    EXPECT_TRUE(std::filesystem::is_empty(scratch.path()));
    // By default the runs go beside the output; only the three files are left there.
    const auto besideOutput =
        runCli({"sort", lion, dir.file("beside.oms"), "--memory-budget", "4M"});
    ASSERT_EQ(besideOutput.exitCode, 0) << besideOutput.err;
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 4);
}

TEST(CliMemoryBudget, SpilledBuildGivesTheSameLevels) {
    OMICRON_REQUIRE_SHARED_FILE(dragon, "dragon.ply");
    TempDir scratch;
    const auto reference = runCli({"build", dragon, "--json"});
    ASSERT_EQ(reference.exitCode, 0) << reference.err;
    EXPECT_TRUE(contains(reference.out, "\"sort_runs\":0")) << reference.out;
    const auto spilled = runCli({"build", dragon, "--json", "--memory-budget", "4M", "--temp-dir",
                                 scratch.path().string()});
    ASSERT_EQ(spilled.exitCode, 0) << spilled.err;
    EXPECT_FALSE(contains(spilled.out, "\"sort_runs\":0")) << spilled.out;
    // Runs merged from disk have no input pages to move into the cloud.
    EXPECT_TRUE(contains(reference.out, "\"recycled_bytes\":")) << reference.out;
    EXPECT_TRUE(contains(spilled.out, "\"recycled_bytes\":0,")) << spilled.out;
    EXPECT_FALSE(levelsOf(reference.out).empty());
    EXPECT_EQ(levelsOf(spilled.out), levelsOf(reference.out));
    EXPECT_TRUE(std::filesystem::is_empty(scratch.path()));
    const auto text =
        runCli({"build", dragon, "--memory-budget", "4M", "--temp-dir", scratch.path().string()});
    EXPECT_TRUE(contains(text.out, "beyond the memory budget:")) << text.out;
}

// Beyond the budget the cloud is in a scratch file and the save sweeps it in batches of an
// eighth of the budget: the same file as the build in memory.
TEST(CliMemoryBudget, SaveBeyondTheBudgetWritesTheSameFile) {
    OMICRON_REQUIRE_SHARED_FILE(dragon, "dragon.ply");
    TempDir dir;
    const auto reference = runCli({"build", dragon, "--save", dir.file("reference.omh")});
    ASSERT_EQ(reference.exitCode, 0) << reference.err;
    const auto spilled = runCli({"build", dragon, "--memory-budget", "4M", "--temp-dir",
                                 dir.path().string(), "--save", dir.file("spilled.omh")});
    ASSERT_EQ(spilled.exitCode, 0) << spilled.err;
    EXPECT_TRUE(contains(spilled.out, "beyond the memory budget:")) << spilled.out;
    EXPECT_EQ(test::readBytes(dir.file("spilled.omh")), test::readBytes(dir.file("reference.omh")));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 2);
}

struct BudgetUsage {
    const char* name;
    std::vector<std::string> args;
    std::string reason;
};

class CliMemoryBudgetUsage : public testing::TestWithParam<BudgetUsage> {};

TEST_P(CliMemoryBudgetUsage, ExitsTwoWithTheReason) {
    const auto run = runCli(GetParam().args);
    EXPECT_EQ(run.exitCode, 2) << run.err;
    EXPECT_TRUE(contains(run.err, GetParam().reason)) << run.err;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CliMemoryBudgetUsage,
    testing::Values(
        BudgetUsage{"BadSuffix",
                    {"sort", "in.ply", "out.oms", "--memory-budget", "12X"},
                    "sort: bad size for --memory-budget: '12X' (expected e.g. 512M, 4G"},
        BudgetUsage{"TooSmall",
                    {"build", "in.ply", "--memory-budget", "1M"},
                    "build: --memory-budget 1M is below the minimum of 4 MiB"},
        BudgetUsage{"NoSuchFolder",
                    {"convert", "in.ply", "out.oms", "--temp-dir", "/nonexistent/scratch"},
                    "convert: --temp-dir '/nonexistent/scratch' is not an existing folder"},
        BudgetUsage{"RenderToo",
                    {"render", "in.ply", "out.png", "--memory-budget", "lots"},
                    "render: bad size for --memory-budget: 'lots'"}),
    [](const auto& info) { return std::string(info.param.name); });

// A sort of autzen_south under the smallest budget into `scratch`, returned once it has a
// scratch file open there (a run being written).
std::unique_ptr<test::RunningProcess>
startSpillingSort(const std::string& input, const TempDir& dir, const TempDir& scratch) {
    std::filesystem::create_directory(dir.path() / "out");
    auto child = std::make_unique<test::RunningProcess>(
        OMICRON_CLI_PATH,
        std::vector<std::string>{"sort", input, (dir.path() / "out" / "south.oms").string(),
                                 "--memory-budget", "4M", "--temp-dir", scratch.path().string()},
        std::vector<std::string>{}, dir.file("stderr.txt"));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (test::openFilesIn(child->pid(), scratch.path()).size() == 0 &&
           std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    EXPECT_GT(test::openFilesIn(child->pid(), scratch.path()).size(), 0u)
        << "no sorted run appeared";
    return child;
}

// Ctrl+C while the sort spills: exit 130, and neither the runs nor the output remain.
TEST(CliMemoryBudget, InterruptRemovesTheRunsAndTheOutput) {
    OMICRON_REQUIRE_SHARED_FILE(south, "autzen_south.ply");
    TempDir dir;
    TempDir scratch;
    const auto child = startSpillingSort(south, dir, scratch);
    child->signal(SIGINT);
    const std::optional<int> status = child->waitFor(std::chrono::seconds(60));
    ASSERT_TRUE(status.has_value()) << "sort did not stop after SIGINT";
    const std::vector<std::uint8_t> err = test::readBytes(dir.file("stderr.txt"));
    EXPECT_EQ(*status, 130) << std::string(err.begin(), err.end());
    EXPECT_TRUE(std::filesystem::is_empty(scratch.path()));
    EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "out"));
}

// Killed outright (SIGKILL, or the out-of-memory killer) while the sort spills, the process
// cleans up nothing, and still nothing remains: its scratch files and its output's temporary
// have no names.
TEST(CliMemoryBudget, AKilledSortLeavesNoScratchFiles) {
    OMICRON_REQUIRE_SHARED_FILE(south, "autzen_south.ply");
    TempDir dir;
    TempDir scratch;
    const auto child = startSpillingSort(south, dir, scratch);
    child->kill();
    EXPECT_TRUE(std::filesystem::is_empty(scratch.path()));
    EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "out"));
}

} // namespace
} // namespace omicron
