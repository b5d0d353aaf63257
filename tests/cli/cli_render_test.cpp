// omicron-cli render's eye-dome lighting: --edl and --no-edl give different images of an
// uncoloured cloud; by default (auto) the bunny (no colours) is shaded and the lion (colours)
// is not; both flags at once are a usage error. Needs a display (the suite runs under Xvfb).
#include "run_process.hpp"
#include "test_files.hpp"

#include <cstdlib>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace omicron {
namespace {

using test::TempDir;

test::ProcessResult runCli(const std::vector<std::string>& args) {
    return test::runProcess(OMICRON_CLI_PATH, args);
}

// Renders `cloud` small with `flags`; the PNG's bytes (the renderer is deterministic).
std::vector<std::uint8_t> render(const std::string& cloud, const TempDir& dir,
                                 const std::string& name, std::vector<std::string> flags) {
    std::vector<std::string> args = {"render", cloud, dir.file(name), "--size", "320x240"};
    args.insert(args.end(), flags.begin(), flags.end());
    const auto run = runCli(args);
    EXPECT_EQ(run.exitCode, 0) << run.err;
    return test::readBytes(dir.file(name));
}

TEST(CliRender, EyeDomeLightingOnOffAndAutomatic) {
    if (std::getenv("DISPLAY") == nullptr) {
        GTEST_SKIP() << "no DISPLAY: omicron-cli render needs an X server (run under xvfb-run)";
    }
    OMICRON_REQUIRE_SHARED_FILE(bunny, "bunny.ply");
    OMICRON_REQUIRE_SHARED_FILE(lion, "lion.ply");
    TempDir dir;
    const auto bunnyOn = render(bunny, dir, "bunny-on.png", {"--edl"});
    const auto bunnyOff = render(bunny, dir, "bunny-off.png", {"--no-edl"});
    const auto bunnyAuto = render(bunny, dir, "bunny-auto.png", {});
    EXPECT_NE(bunnyOn, bunnyOff);
    EXPECT_EQ(bunnyAuto, bunnyOn);
    const auto lionOff = render(lion, dir, "lion-off.png", {"--no-edl"});
    const auto lionAuto = render(lion, dir, "lion-auto.png", {});
    EXPECT_EQ(lionAuto, lionOff);

    const auto both = runCli({"render", bunny, dir.file("x.png"), "--edl", "--no-edl"});
    EXPECT_EQ(both.exitCode, 2);
    EXPECT_NE(both.err.find("--edl and --no-edl"), std::string::npos) << both.err;
}

} // namespace
} // namespace omicron
