// LAS writer: every point format round-trips through the LAS reader, and the bytes it writes
// sit where the LAS specification puts them.
#include "io/input_error.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_reader.hpp"
#include "io/las/las_writer.hpp"
#include "test_files.hpp"

#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <random>
#include <string>
#include <vector>

namespace omicron {
namespace {

// Georeferenced coordinates, as LAS files hold them: an offset keeps them in int32.
const glm::dvec3 kOffset{500000.0, 4000000.0, 0.0};
const glm::dvec3 kScale{0.001};

struct SourceCloud {
    std::vector<glm::dvec3> source; // what the points should read back as
    PointBatch batch;
    CubeTransform cube;
};

SourceCloud makeCloud(std::size_t count, AttributeSet attributes, std::uint32_t seed = 7) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    SourceCloud cloud;
    Bounds bounds;
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 p = kOffset + glm::dvec3(100.0 * unit(random), 80.0 * unit(random),
                                                  100.0 + 20.0 * unit(random));
        cloud.source.push_back(p);
        bounds.extend(p);
    }
    cloud.cube = CubeTransform::fromBounds(bounds);
    cloud.batch.attributes = attributes;
    for (std::size_t i = 0; i < count; ++i) {
        cloud.batch.positions.push_back(cloud.cube.toUnit(cloud.source[i]));
        if (attributes.has(Attribute::Color)) {
            cloud.batch.colors.push_back(glm::u8vec3(random() % 256, random() % 256, i % 256));
        }
        if (attributes.has(Attribute::Intensity)) {
            cloud.batch.intensities.push_back(static_cast<std::uint16_t>(random() % 65536));
        }
    }
    return cloud;
}

LasWriteOptions options(std::uint8_t versionMinor, std::uint8_t pointFormat) {
    LasWriteOptions o;
    o.versionMinor = versionMinor;
    o.pointFormat = pointFormat;
    o.scale = kScale;
    o.offset = kOffset;
    return o;
}

struct ReadBack {
    CloudInfo info;
    PointBatch points;
    ReadSummary summary;
};

ReadBack readBack(const std::string& path, const ReadOptions& readOptions = {}) {
    auto reader = openLasReader(path, {});
    ReadBack result;
    result.info = reader->info();
    result.points.attributes = result.info.attributes;
    result.summary = reader->read(
        [&](const PointBatch& batch) {
            EXPECT_TRUE(batch.consistent());
            const auto append = [](auto& to, const auto& from) {
                to.insert(to.end(), from.begin(), from.end());
            };
            append(result.points.positions, batch.positions);
            append(result.points.colors, batch.colors);
            append(result.points.intensities, batch.intensities);
        },
        readOptions);
    return result;
}

template <typename T> T field(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
    T value;
    std::memcpy(&value, &bytes.at(offset), sizeof value);
    return value;
}

// Half a quantisation step plus float rounding in the unit cube of a 100-unit edge.
constexpr double kPositionTolerance = 0.0005 + 1e-4;

void expectSamePositions(const SourceCloud& cloud, const ReadBack& back) {
    ASSERT_EQ(back.points.size(), cloud.source.size());
    for (std::size_t i = 0; i < cloud.source.size(); ++i) {
        const glm::dvec3 got = back.info.cube.toSource(back.points.positions[i]);
        ASSERT_NEAR(got.x, cloud.source[i].x, kPositionTolerance) << "point " << i;
        ASSERT_NEAR(got.y, cloud.source[i].y, kPositionTolerance) << "point " << i;
        ASSERT_NEAR(got.z, cloud.source[i].z, kPositionTolerance) << "point " << i;
    }
}

struct RoundTripCase {
    std::uint8_t versionMinor;
    std::uint8_t pointFormat;
    bool batchHasColor;
};

std::vector<RoundTripCase> everyVersionAndFormat() {
    std::vector<RoundTripCase> cases;
    for (std::uint8_t versionMinor : {2, 4}) {
        const std::uint8_t lastFormat = versionMinor == 2 ? 5 : 10;
        for (std::uint8_t format = 0; format <= lastFormat; ++format) {
            cases.push_back({versionMinor, format, false});
            cases.push_back({versionMinor, format, true});
        }
    }
    return cases;
}

class LasWriterRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(LasWriterRoundTrip, ReadsBackEveryPointAndAttribute) {
    const RoundTripCase c = GetParam();
    test::TempDir dir;
    const std::string path = dir.file("cloud.las");
    const AttributeSet attributes = c.batchHasColor
                                        ? AttributeSet(Attribute::Intensity) | Attribute::Color
                                        : AttributeSet(Attribute::Intensity);
    const SourceCloud cloud = makeCloud(1500, attributes);
    writeLas(path, cloud.batch, cloud.cube, options(c.versionMinor, c.pointFormat));

    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::uint16_t recordLength = las::minimumRecordLength(c.pointFormat);
    const std::uint16_t headerSize = c.versionMinor == 4 ? 375 : 227;
    ASSERT_EQ(bytes.size(), headerSize + 1500u * recordLength);
    EXPECT_EQ(bytes[las::field::versionMinor], c.versionMinor);
    EXPECT_EQ(bytes[las::field::pointFormat], c.pointFormat);
    EXPECT_EQ(field<std::uint16_t>(bytes, las::field::recordLength), recordLength);

    const ReadBack back = readBack(path);
    EXPECT_EQ(back.info.format, CloudFormat::Las);
    EXPECT_EQ(back.info.pointCount, 1500u);
    EXPECT_TRUE(back.info.boundsFromHeader);
    EXPECT_EQ(back.info.sourceOffset, kOffset);
    EXPECT_EQ(back.summary.pointsDelivered, 1500u);
    EXPECT_EQ(back.summary.skippedNonFinite, 0u);
    const std::string expectedDetail = "LAS 1." + std::to_string(c.versionMinor) +
                                       ", point format " + std::to_string(c.pointFormat) + ", " +
                                       std::to_string(recordLength) + "-byte records";
    EXPECT_EQ(back.info.formatDetail.rfind(expectedDetail, 0), 0u) << back.info.formatDetail;
    expectSamePositions(cloud, back);
    EXPECT_EQ(back.points.intensities, cloud.batch.intensities);

    const bool formatHasColor = las::formatHasColor(c.pointFormat);
    EXPECT_EQ(back.info.attributes.has(Attribute::Color), formatHasColor);
    if (formatHasColor && c.batchHasColor) {
        EXPECT_EQ(back.points.colors, cloud.batch.colors);
        EXPECT_NE(back.info.formatDetail.find("16-bit colour scaled to 8 bits"), std::string::npos)
            << back.info.formatDetail;
    } else if (formatHasColor) {
        EXPECT_EQ(back.points.colors, BatchColumn<glm::u8vec3>(1500, glm::u8vec3(0)));
    }
}

INSTANTIATE_TEST_SUITE_P(LasFormats, LasWriterRoundTrip,
                         ::testing::ValuesIn(everyVersionAndFormat()),
                         [](const ::testing::TestParamInfo<RoundTripCase>& info) {
                             return "Las1" + std::to_string(info.param.versionMinor) + "Format" +
                                    std::to_string(info.param.pointFormat) +
                                    (info.param.batchHasColor ? "WithColor" : "WithoutColor");
                         });

TEST(LasWriterTest, ColourIsWrittenTimes257AndReadBackAsTheSame8BitValues) {
    test::TempDir dir;
    const std::string path = dir.file("colour.las");
    SourceCloud cloud = makeCloud(4, AttributeSet(Attribute::Color));
    cloud.batch.colors = {{255, 0, 1}, {128, 254, 2}, {0, 0, 0}, {17, 200, 255}};
    writeLas(path, cloud.batch, cloud.cube, options(2, 2));

    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::size_t red = 227 + las::colorOffset(2);
    EXPECT_EQ(field<std::uint16_t>(bytes, red), 65535);
    EXPECT_EQ(field<std::uint16_t>(bytes, red + 2), 0);
    EXPECT_EQ(field<std::uint16_t>(bytes, red + 4), 257);
    EXPECT_EQ(field<std::uint16_t>(bytes, red + 26), 128 * 257);

    const ReadBack back = readBack(path);
    EXPECT_EQ(back.points.colors, cloud.batch.colors);
    EXPECT_TRUE(back.info.attributes.has(Attribute::Intensity));
    EXPECT_EQ(back.points.intensities, BatchColumn<std::uint16_t>(4, 0));
}

TEST(LasWriterTest, HeaderFieldsSitAtTheirSpecificationOffsets) {
    test::TempDir dir;
    for (std::uint8_t versionMinor : {2, 4}) {
        const std::string path = dir.file("header.las");
        const SourceCloud cloud = makeCloud(10, AttributeSet(Attribute::Intensity));
        writeLas(path, cloud.batch, cloud.cube, options(versionMinor, 1));
        const std::vector<std::uint8_t> bytes = test::readBytes(path);
        const std::uint16_t headerSize = versionMinor == 4 ? 375 : 227;
        EXPECT_EQ(std::memcmp(bytes.data(), "LASF", 4), 0);
        EXPECT_EQ(bytes[24], 1);
        EXPECT_EQ(bytes[25], versionMinor);
        EXPECT_EQ(field<std::uint16_t>(bytes, 94), headerSize);
        EXPECT_EQ(field<std::uint32_t>(bytes, 96), headerSize);
        EXPECT_EQ(field<std::uint32_t>(bytes, 100), 0u);
        EXPECT_EQ(bytes[104], 1);
        EXPECT_EQ(field<std::uint16_t>(bytes, 105), 28);
        EXPECT_EQ(field<std::uint32_t>(bytes, 107), 10u);
        EXPECT_EQ(field<double>(bytes, 131), 0.001);
        EXPECT_EQ(field<double>(bytes, 155), kOffset.x);
        EXPECT_EQ(field<double>(bytes, 163), kOffset.y);
        // Max and min x, y, z are those of the stored integers, scaled back.
        for (int axis = 0; axis < 3; ++axis) {
            double lowest = 1e300;
            double highest = -1e300;
            for (std::size_t i = 0; i < 10; ++i) {
                const std::int32_t stored =
                    field<std::int32_t>(bytes, headerSize + i * 28 + 4 * axis);
                lowest = std::min(lowest, stored * 0.001 + kOffset[axis]);
                highest = std::max(highest, stored * 0.001 + kOffset[axis]);
            }
            EXPECT_EQ(field<double>(bytes, 179 + 16 * axis), highest);
            EXPECT_EQ(field<double>(bytes, 187 + 16 * axis), lowest);
        }
        // Every point is return 1 of 1.
        EXPECT_EQ(bytes[headerSize + 14], 0x09);
        if (versionMinor == 4) {
            EXPECT_EQ(field<std::uint64_t>(bytes, 247), 10u);
            EXPECT_EQ(field<std::uint64_t>(bytes, 255), 10u);
        }
    }
}

TEST(LasWriterTest, Las14PointFormats6To10LeaveTheLegacyCountZero) {
    test::TempDir dir;
    const std::string path = dir.file("format6.las");
    const SourceCloud cloud = makeCloud(10, AttributeSet(Attribute::Intensity));
    writeLas(path, cloud.batch, cloud.cube, options(4, 6));
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    EXPECT_EQ(field<std::uint32_t>(bytes, 107), 0u);
    EXPECT_EQ(field<std::uint64_t>(bytes, 247), 10u);
    EXPECT_EQ(field<std::uint16_t>(bytes, 6) & 0x10, 0x10); // WKT bit, required for 6..10
    EXPECT_EQ(bytes[375 + 14], 0x11);                       // return 1 of 1, 4-bit fields
    EXPECT_EQ(readBack(path).summary.pointsDelivered, 10u);
}

TEST(LasWriterTest, VariableLengthRecordsLieBetweenHeaderAndPoints) {
    test::TempDir dir;
    const std::string path = dir.file("vlrs.las");
    const SourceCloud cloud = makeCloud(300, AttributeSet(Attribute::Intensity));
    LasWriteOptions o = options(2, 0);
    o.vlrs.push_back({"LASF_Projection", 34735, "GeoKeyDirectoryTag", {1, 0, 1, 0, 0, 0, 0, 0}});
    o.vlrs.push_back({"omicron", 7, "a test record", std::vector<std::uint8_t>(1000, 0xAB)});
    writeLas(path, cloud.batch, cloud.cube, o);

    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::uint32_t pointData = 227 + 54 + 8 + 54 + 1000;
    EXPECT_EQ(field<std::uint32_t>(bytes, 96), pointData);
    EXPECT_EQ(field<std::uint32_t>(bytes, 100), 2u);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(&bytes[227 + 2])), "LASF_Projection");
    EXPECT_EQ(field<std::uint16_t>(bytes, 227 + 18), 34735);
    EXPECT_EQ(field<std::uint16_t>(bytes, 227 + 20), 8);
    EXPECT_EQ(field<std::uint16_t>(bytes, 227 + 54 + 8 + 20), 1000);
    EXPECT_EQ(bytes.size(), pointData + 300u * 20);

    const ReadBack back = readBack(path);
    expectSamePositions(cloud, back);
    EXPECT_EQ(back.points.intensities, cloud.batch.intensities);
}

TEST(LasWriterTest, ExtraBytesPerRecordAreWrittenAndSkippedByTheReader) {
    test::TempDir dir;
    const std::string path = dir.file("extra.las");
    const SourceCloud cloud = makeCloud(500, AttributeSet(Attribute::Intensity) | Attribute::Color);
    LasWriteOptions o = options(4, 7);
    o.extraBytesPerRecord = 9;
    writeLas(path, cloud.batch, cloud.cube, o);

    std::vector<std::uint8_t> bytes = test::readBytes(path);
    ASSERT_EQ(field<std::uint16_t>(bytes, 105), 36 + 9);
    ASSERT_EQ(bytes.size(), 375u + 500 * 45);
    // Fill the extra bytes with a pattern that would corrupt the next record if misread.
    for (std::size_t i = 0; i < 500; ++i) {
        std::memset(&bytes[375 + i * 45 + 36], 0xFF, 9);
    }
    test::writeBytes(path, bytes);

    const ReadBack back = readBack(path);
    EXPECT_EQ(back.info.formatDetail.rfind("LAS 1.4, point format 7, 45-byte records (9 extra "
                                           "bytes), 16-bit colour scaled to 8 bits",
                                           0),
              0u)
        << back.info.formatDetail;
    expectSamePositions(cloud, back);
    EXPECT_EQ(back.points.colors, cloud.batch.colors);
    EXPECT_EQ(back.points.intensities, cloud.batch.intensities);
}

TEST(LasWriterTest, AttributesTheBatchLacksAreWrittenAsZero) {
    test::TempDir dir;
    const std::string path = dir.file("bare.las");
    const SourceCloud cloud = makeCloud(20, AttributeSet());
    writeLas(path, cloud.batch, cloud.cube, options(2, 3));
    const ReadBack back = readBack(path);
    expectSamePositions(cloud, back);
    EXPECT_EQ(back.points.intensities, BatchColumn<std::uint16_t>(20, 0));
    EXPECT_EQ(back.points.colors, BatchColumn<glm::u8vec3>(20, glm::u8vec3(0)));
}

TEST(LasWriterTest, EmptyBatchWritesAHeaderThatTheReaderRejectsAsNoPoints) {
    test::TempDir dir;
    const std::string path = dir.file("empty.las");
    writeLas(path, PointBatch{}, CubeTransform{}, options(2, 0));
    EXPECT_EQ(test::readBytes(path).size(), 227u);
    try {
        openLasReader(path, {});
        FAIL() << "expected NoPoints";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::NoPoints);
        EXPECT_EQ(std::string(error.what()).rfind(path + ": byte 107: ", 0), 0u) << error.what();
    }
}

// A failed write leaves an existing target untouched.
void expectWriteFails(const LasWriteOptions& o, const SourceCloud& cloud,
                      const std::string& expectedText) {
    test::TempDir dir;
    const std::string path = dir.file("target.las");
    test::writeText(path, "previous content");
    try {
        writeLas(path, cloud.batch, cloud.cube, o);
        FAIL() << "expected OutputError containing: " << expectedText;
    } catch (const OutputError& error) {
        const std::string message = error.what();
        EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
        EXPECT_NE(message.find(expectedText), std::string::npos) << message;
    }
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "previous content");
    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
        ++entries;
    }
    EXPECT_EQ(entries, 1u) << "no temporary file is left behind";
}

TEST(LasWriterTest, RejectsOptionsLasCannotHold) {
    const SourceCloud cloud = makeCloud(10, AttributeSet(Attribute::Intensity));
    expectWriteFails(options(2, 6), cloud, "point format 6 needs LAS 1.4");
    expectWriteFails(options(3, 0), cloud, "expected version 1.2 or 1.4");
    expectWriteFails(options(4, 11), cloud, "expected 0 to 10");
    LasWriteOptions zeroScale = options(2, 0);
    zeroScale.scale.y = 0.0;
    expectWriteFails(zeroScale, cloud, "not a finite positive number");
    LasWriteOptions longUserId = options(2, 0);
    longUserId.vlrs.push_back({"a user id longer than 16", 1, "", {}});
    expectWriteFails(longUserId, cloud, "exceeds the LAS limits");
}

TEST(LasWriterTest, RejectsCoordinatesOutsideInt32) {
    const SourceCloud cloud = makeCloud(10, AttributeSet(Attribute::Intensity));
    LasWriteOptions noOffset = options(2, 0);
    noOffset.offset = glm::dvec3(0.0); // 4,000,000 / 0.001 does not fit in int32
    expectWriteFails(noOffset, cloud, "does not fit in LAS's 32-bit integer coordinates");
}

// Streamed in uneven pieces, the file is byte for byte the one writeLas makes of the whole
// batch, header bounds included (they cover every piece).
TEST(LasStreamWriterTest, PiecesGiveTheSameFileAsOneBatch) {
    for (const std::uint8_t format : {std::uint8_t{3}, std::uint8_t{7}}) {
        const SourceCloud cloud =
            makeCloud(1000, AttributeSet(Attribute::Intensity) | Attribute::Color);
        test::TempDir dir;
        writeLas(dir.file("whole.las"), cloud.batch, cloud.cube, options(4, format));
        LasStreamWriter writer(dir.file("pieces.las"), 1000, cloud.batch.attributes,
                               options(4, format));
        for (const auto& [first, last] : {std::pair{0, 1}, std::pair{1, 1}, std::pair{1, 1000}}) {
            PointBatch piece;
            piece.attributes = cloud.batch.attributes;
            for (int i = first; i < last; ++i) {
                piece.positions.push_back(cloud.batch.positions[i]);
                piece.colors.push_back(cloud.batch.colors[i]);
                piece.intensities.push_back(cloud.batch.intensities[i]);
            }
            writer.append(piece, cloud.cube);
        }
        EXPECT_EQ(writer.pointsWritten(), 1000u);
        writer.finish();
        EXPECT_EQ(test::readBytes(dir.file("whole.las")), test::readBytes(dir.file("pieces.las")));
        expectSamePositions(cloud, readBack(dir.file("pieces.las")));
    }
}

TEST(LasStreamWriterTest, AWrongCountFailsAndLeavesNoFile) {
    const SourceCloud cloud = makeCloud(10, AttributeSet(Attribute::Intensity));
    test::TempDir dir;
    const std::string path = dir.file("short.las");
    {
        LasStreamWriter writer(path, 11, cloud.batch.attributes, options(2, 1));
        writer.append(cloud.batch, cloud.cube);
        try {
            writer.finish();
            FAIL() << "finish() accepted 10 of 11 points";
        } catch (const OutputError& error) {
            EXPECT_NE(std::string(error.what())
                          .find("only 10 points appended, but the header "
                                "declares 11"),
                      std::string::npos)
                << error.what();
        }
    }
    {
        LasStreamWriter writer(path, 15, cloud.batch.attributes, options(2, 1));
        writer.append(cloud.batch, cloud.cube);
        EXPECT_THROW(writer.append(cloud.batch, cloud.cube), OutputError); // 20 > 15
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

} // namespace
} // namespace omicron
