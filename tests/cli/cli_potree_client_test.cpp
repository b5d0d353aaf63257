// The Potree export loaded by a real Potree 2.0 client: omicron-cli export-potree writes a
// scan's folder, tests/web/potree_client.mjs serves it on a loopback port to potree-core
// (three.js) in headless Chromium, which fits the camera to the cloud, loads with an unlimited
// point budget until loading settles, and reports what it loaded. Every input point must be
// there exactly once: the points Potree counts in its visible nodes (numVisiblePoints) and the
// points its decoder delivered both equal the input count (an export that stores a parent's
// sample twice, as omicron's hierarchy holds it, would show more). The screenshot must show the
// cloud. Skipped, with the reason, where node, Chromium or the npm packages are missing
// (scripts/build.sh installs them).
#include "run_process.hpp"
#include "std_regex.hpp"
#include "test_files.hpp"

#include <cstdlib>
#include <filesystem>
#include <gtest/gtest.h>
#include <ostream>
#include <sstream>
#include <unistd.h>

namespace omicron {
namespace {

constexpr int kClientSkipped = 77; // potree_client.mjs: Chromium or the npm packages missing

std::string findOnPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::stringstream folders(path != nullptr ? path : "/usr/bin:/bin");
    std::string folder;
    while (std::getline(folders, folder, ':')) {
        const std::filesystem::path candidate = std::filesystem::path(folder) / program;
        if (!folder.empty() && ::access(candidate.c_str(), X_OK) == 0) {
            return candidate.string();
        }
    }
    return {};
}

// A number field of the client's one-line JSON report; -1 when absent.
double field(const std::string& json, const std::string& name) {
    std::smatch match;
    const std::regex pattern("\"" + name + "\":(-?[0-9.eE+]+)");
    return std::regex_search(json, match, pattern) ? std::stod(match[1]) : -1.0;
}

struct ClientCase {
    const char* file;
    std::uint64_t inputPoints;
    const char* depth; // a few hundred nodes: see below
};

void PrintTo(const ClientCase& scan, std::ostream* out) {
    *out << scan.file;
}

class PotreeClient : public ::testing::TestWithParam<ClientCase> {};

TEST_P(PotreeClient, LoadsEveryInputPointOnce) {
    const ClientCase& scan = GetParam();
    OMICRON_REQUIRE_SHARED_FILE(input, scan.file);
    const std::string node = findOnPath("node");
    if (node.empty()) {
        GTEST_SKIP() << "node is not on PATH (scripts/build.sh installs nodejs)";
    }
    test::TempDir dir;
    const std::string folder = dir.file("potree");
    // A shallow build: the client loads every node with a request of its own and its
    // visibility pass walks every visible node per update, and depth 7 makes tens of
    // thousands of small nodes (the count check is the same at any depth).
    const auto exported = test::runProcess(
        OMICRON_CLI_PATH, {"export-potree", input, folder, "--depth", scan.depth, "--json"});
    ASSERT_EQ(exported.exitCode, 0) << exported.err;
    ASSERT_EQ(field(exported.out, "points"), double(scan.inputPoints)) << exported.out;

    const std::string screenshot = (std::filesystem::current_path() /
                                    ("potree_client_" + test::fileParamName(scan.file) + ".png"))
                                       .string();
    const auto client =
        test::runProcess(node, {OMICRON_WEB_TEST_DIR "/potree_client.mjs", "--cloud", folder,
                                "--screenshot", screenshot, "--timeout-ms", "45000"});
    if (client.exitCode == kClientSkipped) {
        GTEST_SKIP() << "no Potree client here: " << client.out;
    }
    ASSERT_EQ(client.exitCode, 0) << client.out << client.err;
    const std::string& report = client.out;
    EXPECT_NE(report.find("\"ok\":true"), std::string::npos) << report;
    EXPECT_EQ(field(report, "metadataPoints"), double(scan.inputPoints)) << report;
    EXPECT_EQ(field(report, "hierarchyPoints"), double(scan.inputPoints)) << report;
    EXPECT_EQ(field(report, "numVisiblePoints"), double(scan.inputPoints)) << report;
    EXPECT_EQ(field(report, "loadedPoints"), double(scan.inputPoints)) << report;
    EXPECT_EQ(field(report, "visibleNodes"), field(report, "hierarchyNodes")) << report;
    // Not an empty frame: the cloud covers a good part of it, in its own colours.
    EXPECT_GT(field(report, "litPixels"), 0.01 * field(report, "totalPixels")) << report;
    EXPECT_GT(field(report, "distinctColors"), 1000) << report;
    EXPECT_GT(std::filesystem::file_size(screenshot), 10000u) << screenshot;
    std::printf("potree-core loaded %.0f of %llu points in %.0f nodes in %.1f s; screenshot %s\n",
                field(report, "loadedPoints"), static_cast<unsigned long long>(scan.inputPoints),
                field(report, "visibleNodes"), field(report, "seconds"), screenshot.c_str());
}

// A georeferenced LAS scan with intensity and colour, and a PLY statue with colour.
INSTANTIATE_TEST_SUITE_P(SharedScans, PotreeClient,
                         ::testing::Values(ClientCase{"autzen_trim.las", 110000, "5"},
                                           ClientCase{"lion.ply", 341989, "4"}),
                         [](const auto& info) { return test::fileParamName(info.param.file); });

} // namespace
} // namespace omicron
