// XYZ text reader: column layouts, separators, headers and comments, non-finite points, every
// malformed input with its error kind and line, and round trips through writeXyz.
#include "io/input_error.hpp"
#include "io/line_reader.hpp"
#include "io/point_reader.hpp"
#include "io/text_blocks.hpp"
#include "io/xyz/xyz_reader.hpp"
#include "io/xyz/xyz_writer.hpp"
#include "scene/scene_generator.hpp"
#include "test_files.hpp"

#include <atomic>
#include <cmath>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace omicron {
namespace {

using test::TempDir;
using test::writeText;

// Reads `text` saved as `name` in a fresh folder.
struct TextCloud {
    TempDir dir;
    std::string path;
    LoadedCloud cloud;

    explicit TextCloud(const std::string& text, const std::string& name = "cloud.xyz")
        : path(dir.file(name)) {
        writeText(path, text);
        cloud = loadPointCloud(path);
    }

    glm::dvec3 source(std::size_t i) const {
        return cloud.info.cube.toSource(cloud.points.positions.at(i));
    }
};

void expectNear(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance = 1e-5) {
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

TEST(XyzLayout, ThreeColumnsArePositions) {
    const TextCloud t("1 2 3\n4 5 6.5\n-1 0 2\n");
    EXPECT_EQ(t.cloud.info.format, CloudFormat::Xyz);
    EXPECT_EQ(t.cloud.info.pointCount, 3u);
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet());
    EXPECT_EQ(t.cloud.info.formatDetail, "XYZ text, 3 columns (x y z), space-separated");
    ASSERT_EQ(t.cloud.points.size(), 3u);
    ASSERT_TRUE(t.cloud.points.consistent());
    expectNear(t.source(0), {1, 2, 3});
    expectNear(t.source(1), {4, 5, 6.5});
    expectNear(t.source(2), {-1, 0, 2});
    EXPECT_EQ(t.cloud.info.sourceBounds.min, glm::dvec3(-1, 0, 2));
    EXPECT_EQ(t.cloud.info.sourceBounds.max, glm::dvec3(4, 5, 6.5));
    EXPECT_FALSE(t.cloud.info.boundsFromHeader);
    EXPECT_EQ(t.cloud.summary.pointsDelivered, 3u);
}

TEST(XyzLayout, FourColumnsAddIntensity) {
    const TextCloud t("0 0 0 0\n1 1 1 65535\n2 2 2 1200.4\n");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Intensity));
    EXPECT_EQ(t.cloud.points.intensities, (BatchColumn<std::uint16_t>{0, 65535, 1200}));
}

TEST(XyzLayout, SixIntegerColumnsAreColors) {
    const TextCloud t("0 0 0 255 128 0\n1 1 1 0 0 7\n");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Color));
    EXPECT_EQ(t.cloud.info.formatDetail, "XYZ text, 6 columns (x y z r g b), space-separated");
    ASSERT_EQ(t.cloud.points.colors.size(), 2u);
    EXPECT_EQ(t.cloud.points.colors[0], glm::u8vec3(255, 128, 0));
    EXPECT_EQ(t.cloud.points.colors[1], glm::u8vec3(0, 0, 7));
}

TEST(XyzLayout, SixColumnsWithDecimalsAreNormals) {
    const TextCloud t("0 0 0 0.000000 0.000000 1.000000\n1 1 1 0.6 0.8 0\n");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Normal));
    EXPECT_EQ(t.cloud.info.formatDetail, "XYZ text, 6 columns (x y z nx ny nz), space-separated");
    EXPECT_EQ(t.cloud.points.normals[0], glm::vec3(0, 0, 1));
    EXPECT_EQ(t.cloud.points.normals[1], glm::vec3(0.6f, 0.8f, 0.0f));
}

TEST(XyzLayout, SixColumnsAreNormalsWhenAnyLineIsNotAColor) {
    // The first line alone looks like a colour; a later line decides for the whole file.
    const TextCloud t("0 0 0 0 0 1\n1 1 1 0.6 0.8 0\n2 2 2 0 1 0\n");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Normal));
    EXPECT_EQ(t.cloud.points.normals[0], glm::vec3(0, 0, 1));
    EXPECT_EQ(t.cloud.points.normals[2], glm::vec3(0, 1, 0));
}

TEST(XyzLayout, SixColumnsAbove255AreNormalsNotColors) {
    const TextCloud t("0 0 0 0 0 256\n1 1 1 3 4 5\n");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Normal));
}

TEST(XyzLayout, NonFiniteNormalsReadAsZero) {
    const TextCloud t("0 0 0 nan 0.0 1.0\n1 1 1 0.0 0.0 1.0\n");
    EXPECT_EQ(t.cloud.points.normals[0], glm::vec3(0.0f));
    EXPECT_EQ(t.cloud.summary.skippedNonFinite, 0u);
}

TEST(XyzLayout, SevenColumnsArePtsWithLeicaIntensity) {
    const TextCloud t("2\n0 0 0 -2048 10 20 30\n1 2 3 2047 40 50 60\n", "scan.pts");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Intensity) | Attribute::Color);
    EXPECT_EQ(t.cloud.info.formatDetail,
              "XYZ text, 7 columns (x y z intensity r g b), space-separated, 1 header line, "
              "intensity -2048..2047 shifted to 0..4095");
    EXPECT_EQ(t.cloud.points.intensities, (BatchColumn<std::uint16_t>{0, 4095}));
    EXPECT_EQ(t.cloud.points.colors[1], glm::u8vec3(40, 50, 60));
    expectNear(t.source(1), {1, 2, 3});
}

TEST(XyzLayout, SevenColumnsWithPositiveIntensityKeepIt) {
    const TextCloud t("0 0 0 12 10 20 30\n1 2 3 40000 40 50 60\n", "scan.pts");
    EXPECT_EQ(t.cloud.points.intensities, (BatchColumn<std::uint16_t>{12, 40000}));
}

TEST(XyzLayout, FractionalUnitIntensitiesAreScaled) {
    const TextCloud t("0 0 0 0.5\n1 1 1 1\n2 2 2 0\n");
    EXPECT_EQ(t.cloud.points.intensities, (BatchColumn<std::uint16_t>{32768, 65535, 0}));
    EXPECT_NE(t.cloud.info.formatDetail.find("intensity 0..1 scaled to 0..65535"),
              std::string::npos);
}

TEST(XyzLayout, NineColumnsAreColorsThenNormals) {
    const TextCloud t("0 0 0 1 2 3 0 0 1\n5 5 5 255 254 253 1 0 0\n");
    EXPECT_EQ(t.cloud.info.attributes, AttributeSet(Attribute::Color) | Attribute::Normal);
    EXPECT_EQ(t.cloud.points.colors[1], glm::u8vec3(255, 254, 253));
    EXPECT_EQ(t.cloud.points.normals[1], glm::vec3(1, 0, 0));
    EXPECT_EQ(t.cloud.points.normals[0], glm::vec3(0, 0, 1));
}

TEST(XyzSeparators, CommasTabsAndMixedBlanks) {
    const TextCloud comma("1,2,3\n4,5,6\n", "a.csv");
    EXPECT_EQ(comma.cloud.info.formatDetail, "XYZ text, 3 columns (x y z), comma-separated");
    expectNear(comma.source(1), {4, 5, 6});

    const TextCloud tab("1\t2\t3\n4\t5\t6\n", "b.txt");
    EXPECT_EQ(tab.cloud.info.formatDetail, "XYZ text, 3 columns (x y z), tab-separated");
    expectNear(tab.source(1), {4, 5, 6});

    const TextCloud mixed("  1 ,\t2 ,3  \n4   5\t\t6\n+7, -8e0 ,9.5E+0\n");
    ASSERT_EQ(mixed.cloud.points.size(), 3u);
    expectNear(mixed.source(0), {1, 2, 3});
    expectNear(mixed.source(2), {7, -8, 9.5});
}

TEST(XyzHeader, CommentsAndBlankLinesAreSkippedAnywhere) {
    const TextCloud t("# exported by a scanner\n// another comment\n\n1 2 3\n   # indented\n"
                      "\t\n4 5 6\n// end\n");
    EXPECT_EQ(t.cloud.info.pointCount, 2u);
    expectNear(t.source(1), {4, 5, 6});
}

TEST(XyzHeader, CsvHeaderLineIsSkipped) {
    const TextCloud t("X,Y,Z,R,G,B\n1,2,3,10,20,30\n4,5,6,40,50,60\n", "cloud.csv");
    EXPECT_EQ(t.cloud.info.pointCount, 2u);
    EXPECT_EQ(t.cloud.info.formatDetail,
              "XYZ text, 6 columns (x y z r g b), comma-separated, 1 header line");
    EXPECT_EQ(t.cloud.points.colors[0], glm::u8vec3(10, 20, 30));
}

TEST(XyzHeader, PtsCountLineIsSkipped) {
    const TextCloud t("3\n1 2 3\n4 5 6\n7 8 9\n", "scan.pts");
    EXPECT_EQ(t.cloud.info.pointCount, 3u);
    expectNear(t.source(0), {1, 2, 3});
}

TEST(XyzHeader, CrlfLineEndingsAndNoFinalNewline) {
    const TextCloud t("x y z\r\n1 2 3\r\n4 5 6\r\n7 8 9");
    ASSERT_EQ(t.cloud.points.size(), 3u);
    expectNear(t.source(2), {7, 8, 9});
}

TEST(XyzHeader, Utf8ByteOrderMarkIsIgnored) {
    const TextCloud t("\xEF\xBB\xBF"
                      "1 2 3\n4 5 6\n");
    EXPECT_EQ(t.cloud.info.pointCount, 2u);
    EXPECT_EQ(t.cloud.info.formatDetail.find("header"), std::string::npos);
    expectNear(t.source(0), {1, 2, 3});
}

TEST(XyzNonFinite, NanAndInfinityPointsAreSkippedAndCounted) {
    const TextCloud t("1 2 3\nnan 0 0\n0 inf 0\n4 5 6\n0 0 -inf\nNaN 1 1\n");
    EXPECT_EQ(t.cloud.info.pointCount, 6u);
    EXPECT_EQ(t.cloud.summary.skippedNonFinite, 4u);
    EXPECT_EQ(t.cloud.summary.pointsDelivered, 2u);
    EXPECT_EQ(t.cloud.info.sourceBounds.min, glm::dvec3(1, 2, 3));
    EXPECT_EQ(t.cloud.info.sourceBounds.max, glm::dvec3(4, 5, 6));
}

TEST(XyzNonFinite, AttributesOfSkippedPointsAreNotChecked) {
    const TextCloud t("nan nan nan nan 999 0 0\n1 2 3 7 1 2 3\n", "scan.pts");
    EXPECT_EQ(t.cloud.summary.skippedNonFinite, 1u);
    EXPECT_EQ(t.cloud.points.intensities, (BatchColumn<std::uint16_t>{7}));
}

TEST(XyzStreaming, BatchesAreBoundedAndCancelStops) {
    TempDir dir;
    const std::string path = dir.file("many.xyz");
    std::string text;
    for (int i = 0; i < 10; ++i) {
        text += std::to_string(i) + " 0 0\n";
    }
    writeText(path, text);
    auto reader = openPointCloud(path);
    ReadOptions options;
    options.batchPoints = 3;
    std::vector<std::size_t> sizes;
    const ReadSummary summary =
        reader->read([&](const PointBatch& batch) { sizes.push_back(batch.size()); }, options);
    EXPECT_EQ(sizes, (std::vector<std::size_t>{3, 3, 3, 1}));
    EXPECT_EQ(summary.batches, 4u);

    std::atomic<bool> cancel{false};
    options.cancel = &cancel;
    std::size_t delivered = 0;
    const ReadSummary cancelled = openPointCloud(path)->read(
        [&](const PointBatch& batch) {
            delivered += batch.size();
            cancel = true;
        },
        options);
    EXPECT_TRUE(cancelled.cancelled);
    EXPECT_EQ(delivered, 3u);
}

TEST(XyzStreaming, KnownBoundsReplaceThePrePassBounds) {
    TempDir dir;
    const std::string path = dir.file("known.xyz");
    writeText(path, "1 1 1\n2 2 2\n");
    OpenOptions options;
    options.knownBounds = Bounds{glm::dvec3(0.0), glm::dvec3(4.0)};
    const LoadedCloud cloud = loadPointCloud(path, options);
    EXPECT_EQ(cloud.info.cube.edge, 4.0);
    EXPECT_EQ(cloud.points.positions[1], glm::vec3(0.5f));
}

// ---- malformed input: every case names its kind, the file and the line ----

struct MalformedCase {
    const char* name;
    std::string text;
    InputErrorKind kind;
    std::uint64_t line; // 0: no line in the message
    std::vector<std::string> mentions;
};

std::string manyHeaderLines() {
    std::string text;
    for (int i = 0; i < 101; ++i) {
        text += "not a number\n";
    }
    return text + "1 2 3\n";
}

const std::vector<MalformedCase>& malformedCases() {
    static const std::vector<MalformedCase> cases{
        {"NonNumericValue",
         "1 2 3\n4 abc 6\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 2", "expected a number", "'abc'"}},
        {"MoreColumnsThanFirstLine",
         "1 2 3\n4 5 6\n4 5 6 7\n",
         InputErrorKind::MalformedValue,
         3,
         {"expected 3 columns", "line 1", "found 4"}},
        {"FewerColumnsThanFirstLine",
         "1,2,3,4,5,6\n1,2\n",
         InputErrorKind::MalformedValue,
         2,
         {"expected 6 columns", "found 2"}},
        {"UnsupportedColumnCount",
         "# five\n1 2 3 4 5\n",
         InputErrorKind::MalformedValue,
         2,
         {"expected 3 (x y z)", "found 5"}},
        {"EmptyField",
         "1,2,3\n4,,6\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 2", "expected a number, found ''"}},
        {"TrailingGarbageLine",
         "1 2 3\n4 5 6\nend of data\n",
         InputErrorKind::MalformedValue,
         3,
         {"column 1", "'end'"}},
        {"NumberOutOfRange",
         "1 2 3\n1e400 2 3\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 1", "'1e400'"}},
        {"ColorAbove255",
         "0 0 0 1 10 20 30\n1 1 1 1 10 300 30\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 6", "colour", "'300'"}},
        {"FractionalColor",
         "0 0 0 0.5 0 0 0 0 1\n",
         InputErrorKind::MalformedValue,
         1,
         {"column 4", "colour", "'0.5'"}},
        {"IntensityAbove65535",
         "0 0 0 1\n1 1 1 70000\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 4", "intensity", "70000"}},
        {"IntensityBelowLeicaRange",
         "0 0 0 -3000\n1 1 1 5\n",
         InputErrorKind::MalformedValue,
         1,
         {"column 4", "-3000"}},
        {"NegativeAndLargeIntensities",
         "0 0 0 -5\n1 1 1 3000\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 4", "3000"}},
        {"NonFiniteIntensity",
         "0 0 0 1\n1 1 1 nan\n",
         InputErrorKind::MalformedValue,
         2,
         {"column 4", "intensity"}},
        {"TooManyHeaderLines",
         manyHeaderLines(),
         InputErrorKind::MalformedValue,
         101,
         {"within the first 100", "'not a number'"}},
        {"OnlyComments",
         "# nothing\n// here\n\n",
         InputErrorKind::NoPoints,
         0,
         {"found only comments"}},
        {"OnlyNonFinitePoints",
         "nan 0 0\n0 inf 0\n",
         InputErrorKind::NoPoints,
         0,
         {"2 lines, all non-finite"}},
        {"LineLongerThanOneMebibyte",
         "1 2 3\n" + std::string(LineReader::kMaxLineBytes + 10, '7'),
         InputErrorKind::MalformedValue,
         2,
         {"without a line break"}},
    };
    return cases;
}

class XyzMalformedInput : public testing::TestWithParam<std::size_t> {};

TEST_P(XyzMalformedInput, ThrowsItsKindNamingFileAndLine) {
    const MalformedCase& c = malformedCases()[GetParam()];
    TempDir dir;
    const std::string path = dir.file("bad.xyz");
    writeText(path, c.text);
    try {
        loadPointCloud(path);
        FAIL() << c.name << ": expected an InputError";
    } catch (const InputError& error) {
        const std::string what = error.what();
        EXPECT_EQ(error.kind(), c.kind) << c.name << ": " << what;
        EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
        if (c.line != 0) {
            EXPECT_EQ(error.location().unit, InputLocation::Unit::Line) << what;
            EXPECT_EQ(error.location().value, c.line) << what;
            EXPECT_NE(what.find(": line " + std::to_string(c.line) + ": "), std::string::npos)
                << what;
        }
        for (const std::string& mention : c.mentions) {
            EXPECT_NE(what.find(mention), std::string::npos) << "'" << mention << "' in " << what;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, XyzMalformedInput,
                         testing::Range<std::size_t>(0, malformedCases().size()),
                         [](const testing::TestParamInfo<std::size_t>& info) {
                             return std::string(malformedCases()[info.param].name);
                         });

TEST(XyzMalformedFile, EmptyFileIsReportedByDetection) {
    TempDir dir;
    const std::string path = dir.file("empty.xyz");
    writeText(path, "");
    try {
        openPointCloud(path);
        FAIL() << "expected EmptyFile";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::EmptyFile);
        EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
    }
}

TEST(XyzMalformedFile, PointOutsideKnownBoundsThrowsAtReadWithLine) {
    TempDir dir;
    const std::string path = dir.file("outside.xyz");
    writeText(path, "1 1 1\n9 1 1\n");
    OpenOptions options;
    options.knownBounds = Bounds{glm::dvec3(0.0), glm::dvec3(2.0)};
    auto reader = openPointCloud(path, options);
    try {
        reader->read([](const PointBatch&) {});
        FAIL() << "expected OutOfBounds";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::OutOfBounds);
        EXPECT_NE(std::string(error.what()).find(path + ": line 2: "), std::string::npos)
            << error.what();
    }
}

// ---- files of many blocks (parsed in parallel, taken in file order) ----

// `lines` data lines "i  i%1000  0.5  intensity", a comment every 1,000 lines and a
// non-finite point every 7,777: several groups of text blocks.
std::string manyLines(int lines) {
    std::string text = "# x y z intensity\n";
    for (int i = 0; i < lines; ++i) {
        if (i % 1000 == 999) {
            text += "// a comment\n";
        }
        if (i % 7777 == 7776) {
            text += "nan 0 0 0\n";
        }
        text += std::to_string(i) + " " + std::to_string(i % 1000) + " 0.5 " +
                std::to_string(i % 4096) + "\n";
    }
    return text;
}

TEST(XyzLargeFile, EveryPointArrivesOnceInFileOrder) {
    constexpr int kLines = 300'000; // about 6 MB
    const TextCloud t(manyLines(kLines));
    ASSERT_EQ(t.cloud.points.size(), static_cast<std::size_t>(kLines));
    EXPECT_EQ(t.cloud.summary.skippedNonFinite, static_cast<std::uint64_t>(kLines / 7777));
    EXPECT_EQ(t.cloud.info.sourceBounds.max, glm::dvec3(kLines - 1, 999, 0.5));
    for (int i = 0; i < kLines; i += 997) {
        expectNear(t.source(static_cast<std::size_t>(i)), glm::dvec3(i, i % 1000, 0.5), 0.05);
        EXPECT_EQ(t.cloud.points.intensities[static_cast<std::size_t>(i)], i % 4096);
    }
}

// Line number of the data line `i` of manyLines (the header and the comment and non-finite
// lines before it counted).
std::uint64_t lineOfDataLine(int i) {
    return 2 + static_cast<std::uint64_t>(i + (i + 1) / 1000 + (i + 1) / 7777);
}

TEST(XyzLargeFile, TheFirstBadLineOfTheFileIsNamed) {
    constexpr int kLines = 300'000;
    std::string text = manyLines(kLines);
    // Break data lines 60,000 (a column missing) and 150,000 (a word for a number): in one group
    // of blocks on two cores or more, so the later may fail first.
    const auto lineStart = [&](int i) {
        std::size_t at = 0;
        for (std::uint64_t line = 1; line < lineOfDataLine(i); ++line) {
            at = text.find('\n', at) + 1;
        }
        return at;
    };
    const std::size_t late = lineStart(150'000);
    text.replace(late, text.find('\n', late) - late, "1 2 oops 4");
    const std::size_t early = lineStart(60'000);
    text.replace(early, text.find('\n', early) - early, "1 2 3");
    TempDir dir;
    const std::string path = dir.file("bad.xyz");
    writeText(path, text);
    try {
        loadPointCloud(path);
        FAIL() << "expected MalformedValue";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::MalformedValue) << error.what();
        EXPECT_EQ(error.location().value, lineOfDataLine(60'000)) << error.what();
        EXPECT_NE(std::string(error.what()).find("expected 4 columns"), std::string::npos)
            << error.what();
    }
}

TEST(XyzLargeFile, TheFirstPreviewPointsComeWithTheFirstBlock) {
    TempDir dir;
    const std::string path = dir.file("big.xyz");
    writeText(path, manyLines(300'000));
    OpenOptions options;
    std::size_t points = 0;
    std::uint64_t offsetOfFirstPoints = 0;
    options.onPrePassPoints = [&](std::span<const glm::dvec3> sample) {
        points += sample.size();
    };
    options.onPrePassProgress = [&](std::uint64_t offset, std::uint64_t) {
        if (points > 0 && offsetOfFirstPoints == 0) {
            offsetOfFirstPoints = offset;
        }
    };
    openPointCloud(path, options);
    EXPECT_GT(points, 1000u);
    EXPECT_GT(offsetOfFirstPoints, 0u);
    // Not a report's worth of bytes (a MiB) later: the end of the first block of lines, which
    // starts after the header line.
    EXPECT_LE(offsetOfFirstPoints, TextBlockReader::kBlockBytes + manyLines(0).size());
}

// ---- writeXyz round trips ----

TEST(XyzWriter, ColorsAndNormalsRoundTrip) {
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Color) | Attribute::Normal;
    batch.positions = {{0, 0, 0}, {1, 0.5f, 0.25f}, {0.125f, 1.0f / 3.0f, 0.75f}};
    batch.colors = {{1, 2, 3}, {255, 0, 128}, {9, 9, 9}};
    batch.normals = {{0, 0, 1}, {1, 0, 0}, {0.6f, 0.8f, 0}};
    const CubeTransform cube{{635000.25, 848000.5, 400.0}, 1200.0};
    TempDir dir;
    const std::string path = dir.file("out.xyz");
    writeXyz(path, batch, cube);
    const LoadedCloud cloud = loadPointCloud(path);
    EXPECT_EQ(cloud.info.attributes, batch.attributes);
    EXPECT_EQ(cloud.info.formatDetail,
              "XYZ text, 9 columns (x y z r g b nx ny nz), space-separated");
    ASSERT_EQ(cloud.points.size(), 3u);
    EXPECT_EQ(cloud.points.colors, batch.colors);
    for (std::size_t i = 0; i < 3; ++i) {
        const glm::dvec3 written = cube.toSource(batch.positions[i]);
        expectNear(cloud.info.cube.toSource(cloud.points.positions[i]), written, 1e-4);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(cloud.points.normals[i][c], batch.normals[i][c], 1e-6);
        }
    }
}

TEST(XyzWriter, AxisAlignedNormalsAloneStayNormals) {
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Normal);
    batch.positions = {{0, 0, 0}, {1, 1, 1}};
    batch.normals = {{0, 0, 1}, {0, 1, 0}};
    TempDir dir;
    const std::string path = dir.file("normals.xyz");
    writeXyz(path, batch, CubeTransform{});
    const LoadedCloud cloud = loadPointCloud(path);
    EXPECT_EQ(cloud.info.attributes, AttributeSet(Attribute::Normal));
    EXPECT_EQ(cloud.points.normals, batch.normals);
}

TEST(XyzWriter, IntensityWithoutNormalsRoundTripsWithOffset) {
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Intensity) | Attribute::Color;
    batch.positions = {{0, 0, 0}, {1, 1, 1}};
    batch.intensities = {17, 65535};
    batch.colors = {{4, 5, 6}, {7, 8, 9}};
    const CubeTransform cube{{1000.0, 2000.0, 3000.0}, 10.0};
    TempDir dir;
    const std::string path = dir.file("scan.pts");
    writeXyz(path, batch, cube, glm::dvec3(1000.0, 2000.0, 3000.0));
    const LoadedCloud cloud = loadPointCloud(path);
    EXPECT_EQ(cloud.info.attributes, batch.attributes);
    EXPECT_EQ(cloud.points.intensities, batch.intensities);
    EXPECT_EQ(cloud.points.colors, batch.colors);
    EXPECT_EQ(cloud.info.sourceBounds.min, glm::dvec3(0.0));
    EXPECT_EQ(cloud.info.sourceBounds.max, glm::dvec3(10.0));
}

TEST(XyzWriter, GeneratedSceneRoundTripsThroughText) {
    const GeneratedScene scene = generateScene(50'000, 11);
    TempDir dir;
    const std::string path = dir.file("scene.xyz");
    writeXyz(path, scene.points, scene.cube);
    auto reader = openPointCloud(path);
    EXPECT_EQ(reader->info().pointCount, 50'000u);
    std::size_t index = 0;
    double worstMetres = 0.0;
    const ReadSummary summary = reader->read([&](const PointBatch& batch) {
        for (std::size_t i = 0; i < batch.size(); ++i, ++index) {
            const glm::dvec3 read = reader->info().cube.toSource(batch.positions[i]);
            const glm::dvec3 original = scene.cube.toSource(scene.points.positions[index]);
            worstMetres = std::max(worstMetres, glm::length(read - original));
            ASSERT_EQ(batch.colors[i], scene.points.colors[index]);
        }
    });
    EXPECT_EQ(summary.pointsDelivered, 50'000u);
    EXPECT_LT(worstMetres, 1e-4); // float resolution of a 300 m cube is 2e-5 m
}

} // namespace
} // namespace omicron
