// XYZ/PTS/TXT/CSV text: layouts, separators, comments and headers, and malformed lines.
#include "input_error.hpp"
#include "point_reader.hpp"
#include "test_files.hpp"
#include "xyz_writer.hpp"

#include <cmath>
#include <gtest/gtest.h>

namespace omicron {
namespace {

LoadedCloud loadText(const test::TempDir& dir, const std::string& name, const std::string& text) {
    const std::string path = dir.file(name);
    test::writeText(path, text);
    return loadPointCloud(path);
}

glm::dvec3 source(const LoadedCloud& cloud, std::size_t i) {
    return cloud.info.cube.toSource(cloud.points.positions[i]);
}

void expectNear(const glm::dvec3& actual, const glm::dvec3& expected) {
    EXPECT_NEAR(actual.x, expected.x, 1e-5);
    EXPECT_NEAR(actual.y, expected.y, 1e-5);
    EXPECT_NEAR(actual.z, expected.z, 1e-5);
}

TEST(XyzLayouts, ThreeColumnsSpaceSeparated) {
    test::TempDir dir;
    const auto cloud = loadText(dir, "a.xyz", "1 2 3\n4 5 6\n-1 0 7.5\n");
    ASSERT_EQ(cloud.points.size(), 3u);
    EXPECT_EQ(cloud.info.format, CloudFormat::Xyz);
    EXPECT_EQ(cloud.info.attributes, AttributeSet());
    expectNear(source(cloud, 2), {-1, 0, 7.5});
    EXPECT_EQ(cloud.info.sourceBounds.min, glm::dvec3(-1, 0, 3));
    EXPECT_EQ(cloud.info.sourceBounds.max, glm::dvec3(4, 5, 7.5));
}

TEST(XyzLayouts, SixIntegerColumnsAreColours) {
    test::TempDir dir;
    const auto cloud = loadText(dir, "c.xyz", "0 0 0 255 0 10\n1 1 1 0 128 255\n");
    ASSERT_TRUE(cloud.info.attributes.has(Attribute::Color));
    EXPECT_FALSE(cloud.info.attributes.has(Attribute::Normal));
    EXPECT_EQ(cloud.points.colors[1], glm::u8vec3(0, 128, 255));
}

TEST(XyzLayouts, SixFractionalColumnsAreNormals) {
    test::TempDir dir;
    const auto cloud = loadText(dir, "n.xyz", "0 0 0 0.0 0.0 1.0\n1 1 1 0.6 0.8 0.0\n");
    ASSERT_TRUE(cloud.info.attributes.has(Attribute::Normal));
    EXPECT_FALSE(cloud.info.attributes.has(Attribute::Color));
    EXPECT_NEAR(cloud.points.normals[1].x, 0.6f, 1e-6);
    EXPECT_NEAR(cloud.points.normals[1].y, 0.8f, 1e-6);
}

TEST(XyzLayouts, NineColumnsColourAndNormal) {
    test::TempDir dir;
    const auto cloud = loadText(dir, "9.xyz", "0 0 0 1 2 3 0 0 1\n2 2 2 4 5 6 1 0 0\n");
    ASSERT_TRUE(cloud.info.attributes.has(Attribute::Color));
    ASSERT_TRUE(cloud.info.attributes.has(Attribute::Normal));
    EXPECT_EQ(cloud.points.colors[1], glm::u8vec3(4, 5, 6));
    EXPECT_EQ(cloud.points.normals[1], glm::vec3(1, 0, 0));
}

TEST(XyzLayouts, PtsWithCountLineIntensityAndColour) {
    test::TempDir dir;
    const auto cloud =
        loadText(dir, "scan.pts", "2\n1.5 2.5 3.5 -2048 10 20 30\n4 5 6 2047 40 50 60\n");
    ASSERT_EQ(cloud.points.size(), 2u);
    ASSERT_TRUE(cloud.info.attributes.has(Attribute::Intensity));
    EXPECT_EQ(cloud.points.intensities[0], 0u);
    EXPECT_EQ(cloud.points.intensities[1], 4095u);
    EXPECT_EQ(cloud.points.colors[1], glm::u8vec3(40, 50, 60));
    expectNear(source(cloud, 0), {1.5, 2.5, 3.5});
}

TEST(XyzLayouts, CsvWithHeaderTabsCommentsAndCrlf) {
    test::TempDir dir;
    const auto cloud = loadText(dir, "t.csv",
                                "X,Y,Z\r\n# a comment\r\n1, 2, 3\r\n// another\r\n\r\n"
                                "4,5,6\r\n");
    ASSERT_EQ(cloud.points.size(), 2u);
    expectNear(source(cloud, 1), {4, 5, 6});
    const auto tabs = loadText(dir, "t.txt", "1\t2\t3\n4\t5\t6\n");
    ASSERT_EQ(tabs.points.size(), 2u);
}

TEST(XyzLayouts, NonFinitePointsAreSkippedAndCounted) {
    test::TempDir dir;
    const std::string path = dir.file("nan.xyz");
    test::writeText(path, "1 2 3\nnan 0 0\n4 inf 6\n7 8 9\n");
    auto reader = openPointCloud(path);
    std::size_t delivered = 0;
    const ReadSummary summary =
        reader->read([&](const PointBatch& batch) { delivered += batch.size(); });
    EXPECT_EQ(delivered, 2u);
    EXPECT_EQ(summary.skippedNonFinite, 2u);
    EXPECT_EQ(reader->info().sourceBounds.max, glm::dvec3(7, 8, 9));
}

TEST(XyzLayouts, WriterRoundTripWithEveryColumnLayout) {
    test::TempDir dir;
    const auto original = loadText(dir, "o.xyz",
                                   "10.25 20.5 30.125 1 2 3 0.0 0.6 0.8\n"
                                   "11 21 31 4 5 6 1.0 0.0 0.0\n"
                                   "12.5 22.75 29 7 8 9 0.0 1.0 0.0\n");
    const std::string copy = dir.file("copy.xyz");
    writeXyz(copy, original.points, original.info.cube);
    const LoadedCloud back = loadPointCloud(copy);
    ASSERT_EQ(back.points.size(), 3u);
    EXPECT_EQ(back.info.attributes, original.info.attributes);
    for (std::size_t i = 0; i < 3; ++i) {
        expectNear(source(back, i), source(original, i));
        EXPECT_EQ(back.points.colors[i], original.points.colors[i]);
        EXPECT_NEAR(back.points.normals[i].y, original.points.normals[i].y, 1e-6);
    }
}

struct MalformedText {
    const char* name;
    const char* text;
    InputErrorKind kind;
    const char* where; // expected "line N: " in the message, or "" for none
};

class XyzMalformed : public ::testing::TestWithParam<MalformedText> {};

TEST_P(XyzMalformed, ReportsKindFileAndLine) {
    const MalformedText& c = GetParam();
    test::TempDir dir;
    const std::string path = dir.file(std::string(c.name) + ".xyz");
    test::writeText(path, c.text);
    try {
        auto reader = openPointCloud(path);
        reader->read([](const PointBatch&) {});
        FAIL() << "no error for " << c.name;
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), c.kind) << error.what();
        const std::string message = error.what();
        EXPECT_EQ(message.rfind(path, 0), 0u) << message;
        EXPECT_NE(message.find(c.where), std::string::npos) << message;
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, XyzMalformed,
    ::testing::Values(
        MalformedText{"column_count_changes", "1 2 3\n4 5 6\n7 8\n", InputErrorKind::MalformedValue,
                      "line 3: "},
        MalformedText{"not_a_number", "1 2 3\n4 five 6\n", InputErrorKind::MalformedValue,
                      "line 2: "},
        MalformedText{"two_columns_only", "1 2\n3 4\n", InputErrorKind::MalformedValue, "line 1"},
        MalformedText{"ten_columns", "1 2 3 4 5 6 7 8 9 10\n", InputErrorKind::MalformedValue,
                      "line 1"},
        MalformedText{"colour_out_of_range", "1 2 3 4 10 20 300\n", InputErrorKind::MalformedValue,
                      "line 1: "},
        MalformedText{"only_comments", "# nothing\n// here\n\n", InputErrorKind::NoPoints, ""},
        MalformedText{"all_non_finite", "nan nan nan\ninf 1 2\n", InputErrorKind::NoPoints, ""},
        MalformedText{"prose", "this is not\na point cloud\nat all\n", InputErrorKind::NoPoints,
                      "header lines"},
        MalformedText{"empty_field", "1,2,3\n1,,3\n", InputErrorKind::MalformedValue, "line 2"},
        MalformedText{"bad_intensity", "1 2 3 70000\n", InputErrorKind::MalformedValue,
                      "line 1: "}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(XyzMalformedFiles, EmptyFileIsRejected) {
    test::TempDir dir;
    const std::string path = dir.file("empty.xyz");
    test::writeText(path, "");
    try {
        openPointCloud(path);
        FAIL();
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::EmptyFile);
        EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
    }
}

} // namespace
} // namespace omicron
