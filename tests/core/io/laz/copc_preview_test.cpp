// COPC: the hierarchy's top levels as a preview at opening. The expected nodes come from the
// root hierarchy page of 1.2-with-color.copc.laz as written by another COPC writer (read with
// a few lines of Python: level 0 holds 24 points, level 1 four nodes of 66 points together,
// 1065 points in all).
#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/las/las_header.hpp"
#include "io/laz/copc_hierarchy.hpp"
#include "io/point_reader.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <cstring>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace omicron {
namespace {

constexpr const char* kCopc = "laz/1.2-with-color.copc.laz";

struct Preview {
    std::vector<glm::dvec3> positions;
    std::vector<glm::u8vec3> colors;
    int calls = 0;
};

Preview openWithPreview(const std::string& path, std::string* detail = nullptr) {
    Preview preview;
    OpenOptions options;
    options.onHierarchyPreview = [&](std::span<const glm::dvec3> positions,
                                     std::span<const glm::u8vec3> colors) {
        preview.positions.assign(positions.begin(), positions.end());
        preview.colors.assign(colors.begin(), colors.end());
        ++preview.calls;
    };
    const auto reader = openPointCloud(path, options);
    if (detail != nullptr) {
        *detail = reader->info().formatDetail;
    }
    return preview;
}

bool lexicalLess(const glm::dvec3& a, const glm::dvec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

TEST(CopcHierarchy, TopNodesAreWholeLevelsWithinTheBudget) {
    OMICRON_REQUIRE_SHARED_FILE(path, kCopc);
    FileStream stream(path);
    const las::Header header = las::readHeader(stream);
    const auto info = laz::readCopcInfo(stream, header);
    ASSERT_TRUE(info.has_value());
    EXPECT_EQ(info->rootPageBytes, 2080u); // 65 entries
    const auto count = [](const std::vector<laz::CopcNode>& nodes) {
        std::uint64_t points = 0;
        for (const laz::CopcNode& node : nodes) {
            points += node.pointCount;
        }
        return points;
    };
    const auto rootOnly = laz::readCopcTopNodes(stream, *info, 10); // level 0 always
    ASSERT_EQ(rootOnly.size(), 1u);
    EXPECT_EQ(rootOnly[0].level, 0);
    EXPECT_EQ(count(rootOnly), 24u);
    const auto twoLevels = laz::readCopcTopNodes(stream, *info, 100);
    EXPECT_EQ(twoLevels.size(), 5u);
    EXPECT_EQ(count(twoLevels), 90u);
    EXPECT_EQ(count(laz::readCopcTopNodes(stream, *info, 1u << 20)), 1065u);
}

TEST(CopcHierarchy, PreviewAtOpeningIsPointsOfTheFileWithTheirColours) {
    OMICRON_REQUIRE_SHARED_FILE(path, kCopc);
    std::string detail;
    Preview preview = openWithPreview(path, &detail);
    EXPECT_NE(detail.find("COPC hierarchy"), std::string::npos) << detail;
    ASSERT_EQ(preview.calls, 1);
    // All 1065 points fit the preview budget: the preview is the whole cloud, every point once.
    const LoadedCloud cloud = loadPointCloud(path);
    ASSERT_EQ(preview.positions.size(), cloud.points.size());
    ASSERT_EQ(preview.colors.size(), cloud.points.size());
    std::vector<glm::dvec3> expected;
    for (const glm::vec3& p : cloud.points.positions) {
        expected.push_back(cloud.info.cube.toSource(p));
    }
    std::sort(expected.begin(), expected.end(), lexicalLess);
    std::sort(preview.positions.begin(), preview.positions.end(), lexicalLess);
    const double tolerance = 1e-6 * cloud.info.cube.edge;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        ASSERT_NEAR(preview.positions[i].x, expected[i].x, tolerance) << i;
        ASSERT_NEAR(preview.positions[i].y, expected[i].y, tolerance) << i;
        ASSERT_NEAR(preview.positions[i].z, expected[i].z, tolerance) << i;
    }
}

TEST(CopcHierarchy, PlainLazHasNoHierarchyPreview) {
    OMICRON_REQUIRE_SHARED_FILE(path, "laz/simple.laz");
    EXPECT_EQ(openWithPreview(path).calls, 0);
}

TEST(CopcHierarchy, ARootPageBeyondTheFileIsAClearError) {
    OMICRON_REQUIRE_SHARED_FILE(path, kCopc);
    test::TempDir dir;
    std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::size_t rootOffsetAt = 375 + 54 + 40; // header, VLR header, info field
    const std::uint64_t beyond = bytes.size() + 100;
    std::memcpy(&bytes[rootOffsetAt], &beyond, 8);
    const std::string broken = dir.file("broken.copc.laz");
    test::writeBytes(broken, bytes);
    try {
        openPointCloud(broken);
        FAIL() << "opened a COPC file whose hierarchy lies beyond its end";
    } catch (const InputError& error) {
        const std::string what = error.what();
        EXPECT_NE(what.find(broken), std::string::npos) << what;
        EXPECT_NE(what.find("COPC"), std::string::npos) << what;
        EXPECT_NE(what.find(std::to_string(rootOffsetAt)), std::string::npos) << what;
    }
}

TEST(CopcHierarchy, ANodeThatIsNoChunkIsAClearError) {
    OMICRON_REQUIRE_SHARED_FILE(path, kCopc);
    test::TempDir dir;
    std::vector<std::uint8_t> bytes = test::readBytes(path);
    // The root page's first entry (the root node): its chunk offset moved by one byte.
    std::uint64_t rootPage;
    std::memcpy(&rootPage, &bytes[375 + 54 + 40], 8);
    std::uint64_t chunk;
    std::memcpy(&chunk, &bytes[rootPage + 16], 8);
    ++chunk;
    std::memcpy(&bytes[rootPage + 16], &chunk, 8);
    const std::string broken = dir.file("broken.copc.laz");
    test::writeBytes(broken, bytes);
    EXPECT_NO_THROW(loadPointCloud(broken)) << "a plain read does not need the hierarchy";
    try {
        openWithPreview(broken);
        FAIL() << "a hierarchy node pointing into a chunk was accepted";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::CorruptData);
        EXPECT_NE(std::string(error.what()).find("not a chunk"), std::string::npos) << error.what();
    }
}

} // namespace
} // namespace omicron
