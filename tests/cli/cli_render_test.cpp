// omicron-cli render's eye-dome lighting: --edl and --no-edl give different images of an
// uncoloured cloud; by default (auto) the bunny (no colours) is shaded and the lion (colours)
// is not; both flags at once are a usage error. Its LAS colour modes: --color classification
// draws the TerraScan tile in its classes' colours. Needs a display (the suite runs under Xvfb).
// And render runs in omicron-cli-render, so that the other commands load no Qt GUI library.
#include "points/asprs_classes.hpp"
#include "run_process.hpp"
#include "test_files.hpp"

#include <QImage>
#include <chrono>
#include <cstdlib>
#include <filesystem>
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

// Pixels of `image` within a few levels of `color`.
int pixelsNear(const QImage& image, glm::u8vec3 color) {
    const QImage rgb = image.convertToFormat(QImage::Format_RGB32);
    int count = 0;
    for (int y = 0; y < rgb.height(); ++y) {
        for (int x = 0; x < rgb.width(); ++x) {
            const QRgb p = rgb.pixel(x, y);
            count += std::abs(qRed(p) - color.r) + std::abs(qGreen(p) - color.g) +
                                 std::abs(qBlue(p) - color.b) <=
                             12
                         ? 1
                         : 0;
        }
    }
    return count;
}

TEST(CliRender, ClassificationColoursTheClasses) {
    if (std::getenv("DISPLAY") == nullptr) {
        GTEST_SKIP() << "no DISPLAY: omicron-cli render needs an X server (run under xvfb-run)";
    }
    OMICRON_REQUIRE_SHARED_FILE(tile, "laz/terrascan_fmt8.laz");
    TempDir dir;
    const auto byClass =
        render(tile, dir, "classes.png", {"--color", "classification", "--no-edl"});
    const auto byRgb = render(tile, dir, "rgb.png", {"--no-edl"});
    EXPECT_NE(byClass, byRgb);
    QImage image;
    ASSERT_TRUE(image.loadFromData(byClass.data(), static_cast<int>(byClass.size()), "PNG"));
    // Mostly ground (683,023 of 697,721 points), with high vegetation (9,003) in patches.
    EXPECT_GT(pixelsNear(image, lasClassColor(2)), 2000);
    EXPECT_GT(pixelsNear(image, lasClassColor(5)), 10);
    QImage rgb;
    ASSERT_TRUE(rgb.loadFromData(byRgb.data(), static_cast<int>(byRgb.size()), "PNG"));
    EXPECT_LT(pixelsNear(rgb, lasClassColor(2)), pixelsNear(image, lasClassColor(2)) / 10);
    // The other LAS modes render too, each its own image.
    const auto byReturn = render(tile, dir, "returns.png", {"--color", "return-number"});
    const auto byGps = render(tile, dir, "gps.png", {"--color", "gps-time"});
    EXPECT_NE(byReturn, byClass);
    EXPECT_NE(byGps, byClass);
    EXPECT_NE(byGps, byReturn);

    const auto unknown = runCli({"render", tile, dir.file("x.png"), "--color", "classes"});
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_NE(unknown.err.find("classification, return-number or gps-time"), std::string::npos)
        << unknown.err;
}

// The libraries a command's process loads, as the dynamic loader reports them.
std::string librariesLoadedBy(const std::string& program, const std::vector<std::string>& args,
                              const TempDir& dir) {
    const std::string log = dir.file("loader.txt");
    test::RunningProcess child(program, args, {"LD_DEBUG=libs"}, log);
    EXPECT_EQ(child.waitFor(std::chrono::seconds(30)), 0);
    const std::vector<std::uint8_t> bytes = test::readBytes(log);
    return {bytes.begin(), bytes.end()};
}

TEST(CliRender, OnlyTheRendererLoadsQtsGuiLibraries) {
    TempDir dir;
    const std::string cli = librariesLoadedBy(OMICRON_CLI_PATH, {"info", "--help"}, dir);
    EXPECT_NE(cli.find("libtbb"), std::string::npos) << cli; // the loader's report is there
    EXPECT_EQ(cli.find("libQt6Gui"), std::string::npos);
    const std::string renderer =
        (std::filesystem::path(OMICRON_CLI_PATH).parent_path() / "omicron-cli-render").string();
    EXPECT_NE(librariesLoadedBy(renderer, {"render", "--help"}, dir).find("libQt6Gui"),
              std::string::npos);
}

TEST(CliRender, WithoutTheRendererBesideItRenderSaysWhatIsMissing) {
    TempDir dir;
    const std::string lone = dir.file("omicron-cli");
    std::filesystem::copy_file(OMICRON_CLI_PATH, lone);
    const auto run = test::runProcess(lone, {"render", "in.ply", dir.file("out.png")});
    EXPECT_EQ(run.exitCode, 1);
    EXPECT_NE(run.err.find(dir.file("omicron-cli-render") + ": cannot start the renderer"),
              std::string::npos)
        << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.png")));
}

} // namespace
} // namespace omicron
