// LAS reader: the real Autzen survey file against its PLY conversion, every header version,
// and malformed files made by corrupting the bytes of valid ones.
#include "io/input_error.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_reader.hpp"
#include "io/las/las_writer.hpp"
#include "io/point_reader.hpp"
#include "test_files.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace omicron {
namespace {

const glm::dvec3 kOffset{300000.0, 5000000.0, 0.0};

// Writes `count` random points (0.001 steps, intensity and colour where the format has it).
std::vector<std::uint8_t> writeValidLas(const std::string& path, std::uint8_t versionMinor,
                                        std::uint8_t pointFormat, std::size_t count,
                                        std::vector<LasVariableLengthRecord> vlrs = {}) {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<glm::dvec3> source;
    Bounds bounds;
    for (std::size_t i = 0; i < count; ++i) {
        source.push_back(kOffset +
                         glm::dvec3(50.0 * unit(random), 40.0 * unit(random), 10.0 * unit(random)));
        bounds.extend(source.back());
    }
    const CubeTransform cube = CubeTransform::fromBounds(bounds);
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Intensity) | Attribute::Color;
    for (std::size_t i = 0; i < count; ++i) {
        batch.positions.push_back(cube.toUnit(source[i]));
        batch.intensities.push_back(static_cast<std::uint16_t>(i));
        batch.colors.push_back(glm::u8vec3(i % 256, (3 * i) % 256, 255));
    }
    LasWriteOptions options;
    options.versionMinor = versionMinor;
    options.pointFormat = pointFormat;
    options.offset = kOffset;
    options.vlrs = std::move(vlrs);
    writeLas(path, batch, cube, options);
    return test::readBytes(path);
}

template <typename T> void put(std::vector<std::uint8_t>& bytes, std::size_t offset, T value) {
    std::memcpy(&bytes.at(offset), &value, sizeof value);
}

template <typename T> T get(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
    T value;
    std::memcpy(&value, &bytes.at(offset), sizeof value);
    return value;
}

std::uint32_t pointDataOffset(const std::vector<std::uint8_t>& bytes) {
    return get<std::uint32_t>(bytes, las::field::pointDataOffset);
}

struct ReadBack {
    CloudInfo info;
    PointBatch points;
    ReadSummary summary;
    std::vector<std::size_t> batchSizes;
};

ReadBack readAll(const std::string& path, const OpenOptions& openOptions = {},
                 const ReadOptions& readOptions = {}) {
    auto reader = openLasReader(path, openOptions);
    ReadBack result;
    result.info = reader->info();
    result.points.attributes = result.info.attributes;
    result.summary = reader->read(
        [&](const PointBatch& batch) {
            EXPECT_TRUE(batch.consistent());
            result.batchSizes.push_back(batch.size());
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

void expectInUnitCube(std::span<const glm::vec3> positions) {
    for (std::size_t i = 0; i < positions.size(); ++i) {
        const glm::vec3 p = positions[i];
        ASSERT_TRUE(p.x >= 0.0f && p.y >= 0.0f && p.z >= 0.0f && p.x <= 1.0f && p.y <= 1.0f &&
                    p.z <= 1.0f)
            << "point " << i << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
    }
}

// Runs `action`, which must throw InputError of `kind` whose message starts with
// "PATH: byte OFFSET: ".
void expectInputError(const std::function<void()>& action, InputErrorKind kind,
                      const std::string& path, std::uint64_t byte) {
    try {
        action();
        ADD_FAILURE() << "expected InputError (" << toString(kind) << ")";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), kind) << "got " << toString(error.kind()) << ": " << error.what();
        const std::string prefix = path + ": byte " + std::to_string(byte) + ": ";
        EXPECT_EQ(std::string(error.what()).rfind(prefix, 0), 0u)
            << "expected the message to start with '" << prefix << "', got: " << error.what();
        EXPECT_FALSE(error.detail().empty());
    }
}

// --- The real file ----------------------------------------------------------------------------

TEST(LasAutzenTest, HeaderDescribesTheSurvey) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.las");
    auto reader = openLasReader(path, {});
    const CloudInfo& info = reader->info();
    EXPECT_EQ(info.format, CloudFormat::Las);
    EXPECT_EQ(info.pointCount, 110000u);
    EXPECT_TRUE(info.boundsFromHeader);
    EXPECT_EQ(info.attributes, AttributeSet(Attribute::Intensity) | Attribute::Color |
                                   Attribute::Las | Attribute::GpsTime);
    EXPECT_EQ(info.sourceOffset, glm::dvec3(0.0));
    EXPECT_EQ(info.formatDetail.rfind("LAS 1.2, point format 3, 34-byte records, 8-bit colour "
                                      "in 16-bit fields",
                                      0),
              0u)
        << info.formatDetail;
    EXPECT_NEAR(info.sourceBounds.min.x, 636001.76, 1e-6);
    EXPECT_NEAR(info.sourceBounds.min.y, 848935.20, 1e-6);
    EXPECT_NEAR(info.sourceBounds.min.z, 406.26, 1e-6);
    EXPECT_NEAR(info.sourceBounds.max.x, 637179.22, 1e-6);
    EXPECT_NEAR(info.sourceBounds.max.y, 849497.90, 1e-6);
    EXPECT_NEAR(info.sourceBounds.max.z, 520.51, 1e-6);
    EXPECT_EQ(info.cube, CubeTransform::fromBounds(info.sourceBounds));
}

TEST(LasAutzenTest, MatchesThePlyConversionPointByPoint) {
    OMICRON_REQUIRE_SHARED_FILE(lasPath, "autzen_trim.las");
    OMICRON_REQUIRE_SHARED_FILE(plyPath, "autzen_trim.ply");
    const ReadBack las = readAll(lasPath);
    const LoadedCloud ply = loadPointCloud(plyPath);
    ASSERT_EQ(las.points.size(), 110000u);
    ASSERT_EQ(ply.points.size(), 110000u);
    // The PLY's source units include its "comment offset 635000 848000 0".
    EXPECT_EQ(ply.info.sourceOffset, glm::dvec3(635000.0, 848000.0, 0.0));
    ASSERT_TRUE(ply.info.attributes.has(Attribute::Color));
    for (std::size_t i = 0; i < las.points.size(); ++i) {
        const glm::dvec3 fromLas = las.info.cube.toSource(las.points.positions[i]);
        const glm::dvec3 fromPly = ply.info.cube.toSource(ply.points.positions[i]);
        ASSERT_NEAR(fromLas.x, fromPly.x, 0.005) << "point " << i;
        ASSERT_NEAR(fromLas.y, fromPly.y, 0.005) << "point " << i;
        ASSERT_NEAR(fromLas.z, fromPly.z, 0.005) << "point " << i;
        ASSERT_EQ(las.points.colors[i], ply.points.colors[i]) << "point " << i;
    }
}

TEST(LasAutzenTest, StreamsEveryPointInBatchesInsideTheUnitCube) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.las");
    ReadOptions options;
    options.batchPoints = 4096;
    const ReadBack back = readAll(path, {}, options);
    EXPECT_EQ(back.summary.pointsDelivered, 110000u);
    EXPECT_EQ(back.summary.skippedNonFinite, 0u);
    EXPECT_FALSE(back.summary.cancelled);
    EXPECT_EQ(back.summary.batches, 27u); // 26 full batches and 3,504 points
    ASSERT_EQ(back.batchSizes.size(), 27u);
    for (std::size_t i = 0; i + 1 < back.batchSizes.size(); ++i) {
        EXPECT_EQ(back.batchSizes[i], 4096u);
    }
    EXPECT_EQ(back.batchSizes.back(), 110000u - 26 * 4096);
    expectInUnitCube(back.points.positions);
    // The header's bounds are tight: some point touches each face of the box.
    glm::vec3 low(1.0f);
    glm::vec3 high(0.0f);
    for (const glm::vec3& p : back.points.positions) {
        low = glm::min(low, p);
        high = glm::max(high, p);
    }
    const glm::dvec3 extent = back.info.sourceBounds.extent() / back.info.cube.edge;
    EXPECT_NEAR(low.x, 0.0, 1e-6);
    EXPECT_NEAR(low.z, 0.0, 1e-6);
    EXPECT_NEAR(high.x, extent.x, 1e-6);
    EXPECT_NEAR(high.y, extent.y, 1e-6);
}

TEST(LasAutzenTest, KnownBoundsReplaceTheHeaderBounds) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.las");
    OpenOptions options;
    options.knownBounds = Bounds{{636000.0, 848900.0, 400.0}, {637200.0, 849500.0, 600.0}};
    const ReadBack back = readAll(path, options);
    EXPECT_FALSE(back.info.boundsFromHeader);
    EXPECT_EQ(back.info.sourceBounds, *options.knownBounds);
    EXPECT_EQ(back.info.cube.origin, options.knownBounds->min);
    EXPECT_EQ(back.info.cube.edge, 1200.0);
    EXPECT_EQ(back.summary.pointsDelivered, 110000u);
    expectInUnitCube(back.points.positions);
}

// The same cancel between batches for the LAS file and its LAZ twin (chunks decoded in
// parallel, delivered in batches all the same).
class LasAndLazCancel : public ::testing::TestWithParam<const char*> {};

TEST_P(LasAndLazCancel, CancelStopsBetweenBatches) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    auto reader = openLasReader(path, {});
    std::atomic<bool> cancel{false};
    ReadOptions options;
    options.batchPoints = 10000;
    options.cancel = &cancel;
    std::size_t seen = 0;
    const ReadSummary summary = reader->read(
        [&](const PointBatch& batch) {
            seen += batch.size();
            if (seen >= 20000) {
                cancel = true;
            }
        },
        options);
    EXPECT_TRUE(summary.cancelled);
    EXPECT_EQ(summary.batches, 2u);
    EXPECT_EQ(summary.pointsDelivered, 20000u);
}

INSTANTIATE_TEST_SUITE_P(Autzen, LasAndLazCancel,
                         ::testing::Values("autzen_trim.las", "laz/autzen_trim.laz"));

TEST(LasAutzenTest, CompressionBitWithoutLaszipRecordIsMalformed) {
    OMICRON_REQUIRE_SHARED_FILE(source, "autzen_trim.las");
    test::TempDir dir;
    std::vector<std::uint8_t> bytes = test::readBytes(source);
    bytes[las::field::pointFormat] |= 0x80; // how LAZ marks its compressed point format
    const std::string path = dir.file("autzen.laz");
    test::writeBytes(path, bytes);
    EXPECT_EQ(detectFormat(path), CloudFormat::Laz);
    expectInputError([&] { openPointCloud(path); }, InputErrorKind::MalformedHeader, path,
                     las::field::pointFormat);
    try {
        openPointCloud(path);
    } catch (const InputError& error) {
        EXPECT_NE(error.detail().find("no 'laszip encoded' variable length record"),
                  std::string::npos)
            << error.what();
    }
}

// LAZ writers may leave the format byte plain: the laszip record alone makes the file LAZ,
// and a record that is not a real one is refused by the LAZ reader, naming its payload.
TEST(LasAutzenTest, LaszipRecordMakesTheFileLazEvenWithAPlainFormatByte) {
    OMICRON_REQUIRE_SHARED_FILE(source, "autzen_trim.las");
    test::TempDir dir;
    std::vector<std::uint8_t> bytes = test::readBytes(source);
    // Turn the third of the five VLRs into the laszip one.
    std::size_t vlr = 227;
    for (int i = 0; i < 2; ++i) {
        vlr += las::kVlrHeaderSize + get<std::uint16_t>(bytes, vlr + 20);
    }
    std::memset(&bytes[vlr + 2], 0, 16);
    std::memcpy(&bytes[vlr + 2], "laszip encoded", 14);
    put<std::uint16_t>(bytes, vlr + 18, las::kLaszipRecordId);
    const std::string path = dir.file("autzen.laz");
    test::writeBytes(path, bytes);
    expectInputError([&] { openPointCloud(path); }, InputErrorKind::UnsupportedFeature, path,
                     vlr + las::kVlrHeaderSize);
    try {
        openPointCloud(path);
    } catch (const InputError& error) {
        EXPECT_NE(error.detail().find("unknown LAZ compressor"), std::string::npos) << error.what();
    }
}

// --- Versions and layouts ---------------------------------------------------------------------

TEST(LasReaderTest, Las10HeaderWithPointDataStartSignature) {
    test::TempDir dir;
    const std::string path = dir.file("v10.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 1, 200);
    const ReadBack expected = readAll(path);
    // LAS 1.0: reserved fields where 1.2 has source id and global encoding, and the two-byte
    // start signature 0xDD 0xCC before the points, counted in the offset to point data.
    bytes[las::field::versionMinor] = 0;
    put<std::uint32_t>(bytes, 4, 0);
    const std::uint32_t points = pointDataOffset(bytes);
    bytes.insert(bytes.begin() + points, {0xDD, 0xCC});
    put<std::uint32_t>(bytes, las::field::pointDataOffset, points + 2);
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_EQ(back.info.formatDetail, "LAS 1.0, point format 1, 28-byte records");
    EXPECT_EQ(back.points.positions, expected.points.positions);
    EXPECT_EQ(back.points.intensities, expected.points.intensities);
}

TEST(LasReaderTest, Las11Header) {
    test::TempDir dir;
    const std::string path = dir.file("v11.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 0, 200);
    const ReadBack expected = readAll(path);
    bytes[las::field::versionMinor] = 1;
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_EQ(back.info.formatDetail, "LAS 1.1, point format 0, 20-byte records");
    EXPECT_EQ(back.points.positions, expected.points.positions);
}

TEST(LasReaderTest, Las13HeaderWithWaveformField) {
    test::TempDir dir;
    const std::string path = dir.file("v13.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 5, 200);
    const ReadBack expected = readAll(path);
    bytes[las::field::versionMinor] = 3;
    bytes.insert(bytes.begin() + 227, 8, 0); // start of waveform data packet record
    put<std::uint16_t>(bytes, las::field::headerSize, 235);
    put<std::uint32_t>(bytes, las::field::pointDataOffset, 235);
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_EQ(back.info.formatDetail.rfind("LAS 1.3, point format 5, 63-byte records", 0), 0u);
    EXPECT_EQ(back.points.positions, expected.points.positions);
    EXPECT_EQ(back.points.colors, expected.points.colors);
}

TEST(LasReaderTest, Las14WithOnlyTheLegacyCountUsesIt) {
    test::TempDir dir;
    const std::string path = dir.file("legacy.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 4, 3, 300);
    put<std::uint64_t>(bytes, las::field::pointCount, 0);
    test::writeBytes(path, bytes);
    EXPECT_EQ(readAll(path).summary.pointsDelivered, 300u);
}

TEST(LasReaderTest, Las14WithOnlyThe64BitCountUsesIt) {
    test::TempDir dir;
    const std::string path = dir.file("format8.las");
    const std::vector<std::uint8_t> bytes = writeValidLas(path, 4, 8, 300);
    ASSERT_EQ(get<std::uint32_t>(bytes, las::field::legacyPointCount), 0u);
    EXPECT_EQ(readAll(path).summary.pointsDelivered, 300u);
}

TEST(LasReaderTest, BytesAfterTheLastRecordAreAllowed) {
    test::TempDir dir;
    const std::string path = dir.file("evlr.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 4, 6, 300);
    bytes.insert(bytes.end(), 1000, 0x5A); // where LAS 1.4 puts its extended VLRs
    test::writeBytes(path, bytes);
    EXPECT_EQ(readAll(path).summary.pointsDelivered, 300u);
}

TEST(LasReaderTest, BatchesHoldAtMostBatchPoints) {
    test::TempDir dir;
    const std::string path = dir.file("batches.las");
    writeValidLas(path, 2, 3, 1000);
    ReadOptions options;
    options.batchPoints = 64;
    const ReadBack back = readAll(path, {}, options);
    EXPECT_EQ(back.summary.batches, 16u);
    EXPECT_EQ(back.summary.pointsDelivered, 1000u);
    ASSERT_EQ(back.batchSizes.size(), 16u);
    EXPECT_EQ(back.batchSizes.front(), 64u);
    EXPECT_EQ(back.batchSizes.back(), 1000u - 15 * 64);
    EXPECT_EQ(back.points.intensities.back(), 999); // file order kept
}

TEST(LasReaderTest, UnusableHeaderBoundsFallBackToAPrePass) {
    test::TempDir dir;
    const std::string path = dir.file("bounds.las");
    const std::vector<std::uint8_t> valid = writeValidLas(path, 2, 0, 500);
    const Bounds declared = readAll(path).info.sourceBounds;
    const auto minX = las::field::bounds + 8;
    const auto maxZ = las::field::bounds + 32;
    std::vector<std::uint8_t> nan = valid;
    put<double>(nan, maxZ, std::numeric_limits<double>::quiet_NaN());
    std::vector<std::uint8_t> inverted = valid;
    put<double>(inverted, minX, get<double>(valid, las::field::bounds) + 1.0);
    for (const auto& bytes : {nan, inverted}) {
        test::writeBytes(path, bytes);
        const ReadBack back = readAll(path);
        EXPECT_FALSE(back.info.boundsFromHeader);
        EXPECT_EQ(back.info.sourceBounds, declared); // the writer's bounds are exact
        EXPECT_EQ(back.summary.pointsDelivered, 500u);
        expectInUnitCube(back.points.positions);
    }
}

TEST(LasReaderTest, PointWithinHalfAStepOfTheHeaderBoundsIsClampedIntoTheCube) {
    test::TempDir dir;
    const std::string path = dir.file("rounded.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 0, 500);
    // Header bounds rounded inwards by 0.4 steps, as a writer printing fewer digits might.
    put<double>(bytes, las::field::bounds, get<double>(bytes, las::field::bounds) - 0.0004);
    put<double>(bytes, las::field::bounds + 8, get<double>(bytes, las::field::bounds + 8) + 0.0004);
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_EQ(back.summary.pointsDelivered, 500u);
    expectInUnitCube(back.points.positions);
}

TEST(LasReaderTest, PointOutsideTheHeaderBoundsNamesItsRecord) {
    test::TempDir dir;
    const std::string path = dir.file("outside.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 1, 500);
    const std::size_t record = pointDataOffset(bytes) + 57 * 28;
    put<std::int32_t>(bytes, record + 8, get<std::int32_t>(bytes, record + 8) + 20000); // z + 20
    test::writeBytes(path, bytes);
    expectInputError([&] { readAll(path); }, InputErrorKind::OutOfBounds, path, record);
    try {
        readAll(path);
    } catch (const InputError& error) {
        EXPECT_NE(error.detail().find("point record 57 (counting from 0)"), std::string::npos)
            << error.what();
        EXPECT_NE(error.detail().find("the header's bounds are wrong"), std::string::npos)
            << error.what();
    }
}

// The reader parses a block a batch's run at a time: a bad point deep in a later run of a
// later batch is still named by its own record.
TEST(LasReaderTest, PointOutsideTheBoundsInALaterBatchNamesItsRecord) {
    test::TempDir dir;
    const std::string path = dir.file("outside-later.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 1, 500);
    const std::size_t record = pointDataOffset(bytes) + 157 * 28;
    put<std::int32_t>(bytes, record + 8, get<std::int32_t>(bytes, record + 8) + 20000);
    test::writeBytes(path, bytes);
    ReadOptions options;
    options.batchPoints = 64; // record 157 is the 30th of the third batch
    std::size_t delivered = 0;
    try {
        openLasReader(path, {})->read([&](const PointBatch& batch) { delivered += batch.size(); },
                                      options);
        FAIL() << "expected OutOfBounds";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::OutOfBounds);
        EXPECT_EQ(error.location().value, record);
        EXPECT_NE(error.detail().find("point record 157 (counting from 0)"), std::string::npos)
            << error.what();
    }
    EXPECT_EQ(delivered, 128u) << "the two whole batches before it, nothing of the third";
}

// A file of several 4 MiB blocks, each read while the one before is parsed, in batches whose
// runs are parsed in slices on several threads: every point arrives once, in file order, with
// its own attributes.
constexpr std::size_t kManyBlocksPoints = 300000; // 34-byte records: 10.2 MB, three blocks

TEST(LasReaderTest, FileOfSeveralBlocksArrivesInOrderWithEveryAttribute) {
    test::TempDir dir;
    const std::string path = dir.file("blocks.las");
    writeValidLas(path, 2, 3, kManyBlocksPoints);
    const ReadBack back = readAll(path);
    ASSERT_EQ(back.summary.pointsDelivered, kManyBlocksPoints);
    ASSERT_EQ(back.points.size(), kManyBlocksPoints);
    expectInUnitCube(back.points.positions);
    // The writer's random source positions again (same seed and order as writeValidLas).
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<glm::dvec3> source(kManyBlocksPoints);
    for (glm::dvec3& p : source) {
        p = kOffset + glm::dvec3(50.0 * unit(random), 40.0 * unit(random), 10.0 * unit(random));
    }
    const CubeTransform& cube = back.info.cube;
    for (std::size_t i = 0; i < kManyBlocksPoints; ++i) {
        ASSERT_EQ(back.points.intensities[i], static_cast<std::uint16_t>(i)) << "point " << i;
        ASSERT_EQ(back.points.colors[i], glm::u8vec3(i % 256, (3 * i) % 256, 255)) << "point " << i;
        const glm::dvec3 read = cube.toSource(back.points.positions[i]);
        ASSERT_NEAR(read.x, source[i].x, 0.002) << "point " << i;
        ASSERT_NEAR(read.y, source[i].y, 0.002) << "point " << i;
        ASSERT_NEAR(read.z, source[i].z, 0.002) << "point " << i;
    }
}

TEST(LasReaderTest, PointOutsideTheBoundsInALaterBlockNamesItsRecord) {
    test::TempDir dir;
    const std::string path = dir.file("outside-block.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 3, kManyBlocksPoints);
    const std::size_t index = 250001; // third block, in a slice after the run's first
    const std::size_t record = pointDataOffset(bytes) + index * 34;
    put<std::int32_t>(bytes, record + 8, get<std::int32_t>(bytes, record + 8) + 20000);
    test::writeBytes(path, bytes);
    expectInputError([&] { readAll(path); }, InputErrorKind::OutOfBounds, path, record);
}

TEST(LasReaderTest, FileCutWhileBeingReadNamesTheRecordsItLacks) {
    test::TempDir dir;
    const std::string path = dir.file("cut.las");
    const std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 3, kManyBlocksPoints);
    auto reader = openLasReader(path, {}); // the header's count matches the file's size here
    const std::uint64_t keep = pointDataOffset(bytes) + 200000 * std::uint64_t{34};
    std::filesystem::resize_file(path, keep); // another program cuts it short meanwhile
    std::size_t delivered = 0;
    try {
        reader->read([&](const PointBatch& batch) { delivered += batch.size(); });
        FAIL() << "expected Truncated";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::Truncated) << error.what();
        EXPECT_EQ(error.location().value, keep) << error.what();
        EXPECT_NE(error.detail().find("record 200000 of 300000"), std::string::npos)
            << error.what();
    }
    EXPECT_LT(delivered, 200000u) << "nothing past the end of what was left";
}

TEST(LasReaderTest, KnownBoundsThatMissAPointFailTheRead) {
    test::TempDir dir;
    const std::string path = dir.file("known.las");
    const std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 0, 500);
    Bounds tooSmall = readAll(path).info.sourceBounds;
    tooSmall.max.x -= 1.0;
    OpenOptions options;
    options.knownBounds = tooSmall;
    auto reader = openLasReader(path, options);
    EXPECT_EQ(reader->info().sourceBounds, tooSmall);
    EXPECT_FALSE(reader->info().boundsFromHeader);
    try {
        reader->read([](const PointBatch&) {});
        FAIL() << "expected OutOfBounds";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::OutOfBounds);
        EXPECT_EQ(error.location().unit, InputLocation::Unit::Byte);
        const std::uint64_t byte = error.location().value;
        EXPECT_GE(byte, pointDataOffset(bytes));
        EXPECT_EQ((byte - pointDataOffset(bytes)) % 20, 0u) << "a record's first byte";
    }
}

TEST(LasReaderTest, EightBitValuesInSixteenBitFieldsAreTakenAsIs) {
    test::TempDir dir;
    const std::string path = dir.file("colour8.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 2, 300);
    const std::size_t first = pointDataOffset(bytes);
    for (std::size_t i = 0; i < 300; ++i) {
        put<std::uint16_t>(bytes, first + i * 26 + 20, static_cast<std::uint16_t>(i % 256));
        put<std::uint16_t>(bytes, first + i * 26 + 22, 7);
        put<std::uint16_t>(bytes, first + i * 26 + 24, 255);
    }
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_EQ(back.info.formatDetail,
              "LAS 1.2, point format 2, 26-byte records, 8-bit colour in 16-bit fields "
              "(judged from 300 sampled records)");
    for (std::size_t i = 0; i < 300; ++i) {
        ASSERT_EQ(back.points.colors[i], glm::u8vec3(i % 256, 7, 255)) << "point " << i;
    }
}

TEST(LasReaderTest, OneSampledValueAbove255MakesTheColour16Bit) {
    test::TempDir dir;
    const std::string path = dir.file("colour16.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 2, 300);
    const std::size_t first = pointDataOffset(bytes);
    for (std::size_t i = 0; i < 300; ++i) {
        put<std::uint16_t>(bytes, first + i * 26 + 20, 100);
        put<std::uint16_t>(bytes, first + i * 26 + 22, 200);
        put<std::uint16_t>(bytes, first + i * 26 + 24, 255);
    }
    put<std::uint16_t>(bytes, first + 299 * 26 + 24, 65535); // only the last record
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_NE(back.info.formatDetail.find("16-bit colour scaled to 8 bits"), std::string::npos);
    // v / 257 rounded: 100 -> 0, 200 -> 1, 255 -> 1, 65535 -> 255.
    EXPECT_EQ(back.points.colors.front(), glm::u8vec3(0, 1, 1));
    EXPECT_EQ(back.points.colors.back(), glm::u8vec3(0, 1, 255));
}

TEST(LasReaderTest, ColourAbove255MissedByTheSampleIsClamped) {
    test::TempDir dir;
    const std::string path = dir.file("sampled.las");
    std::vector<std::uint8_t> bytes = writeValidLas(path, 2, 3, 10000);
    const std::size_t first = pointDataOffset(bytes);
    for (std::size_t i = 0; i < 10000; ++i) {
        for (std::size_t channel = 0; channel < 3; ++channel) {
            put<std::uint16_t>(bytes, first + i * 34 + 28 + 2 * channel, 40);
        }
    }
    // 4096 of 10,000 records are sampled, at s * 10000 / 4096: record 1 is not among them.
    put<std::uint16_t>(bytes, first + 1 * 34 + 28, 300);
    test::writeBytes(path, bytes);
    const ReadBack back = readAll(path);
    EXPECT_NE(back.info.formatDetail.find("8-bit colour in 16-bit fields (judged from 4096 "
                                          "sampled records)"),
              std::string::npos)
        << back.info.formatDetail;
    EXPECT_EQ(back.points.colors[0], glm::u8vec3(40));
    EXPECT_EQ(back.points.colors[1], glm::u8vec3(255, 40, 40));
}

// --- Malformed files --------------------------------------------------------------------------

// A corruption of a valid file (LAS 1.2 or 1.4, point format 3, 100 points, one 10-byte VLR,
// so the points start at byte 291 in 1.2 and 439 in 1.4); it returns the byte offset the
// error must name.
struct Corruption {
    const char* name;
    std::uint8_t versionMinor;
    std::uint64_t (*corrupt)(std::vector<std::uint8_t>& bytes);
    InputErrorKind kind;
};

constexpr std::size_t kRecords = 100;
constexpr std::size_t kRecordLength = 34;

const Corruption kCorruptions[] = {
    {"BadSignature", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b[3] = 'X';
         return 0;
     },
     InputErrorKind::MalformedHeader},
    {"HeaderShorterThanItsBlock", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b.resize(200);
         return 200;
     },
     InputErrorKind::Truncated},
    {"Las14HeaderCutAtByte300", 4,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b.resize(300);
         return 300;
     },
     InputErrorKind::Truncated},
    {"VersionMajor2", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b[las::field::versionMajor] = 2;
         return las::field::versionMajor;
     },
     InputErrorKind::UnsupportedFeature},
    {"VersionMinor5", 4,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b[las::field::versionMinor] = 5;
         return las::field::versionMinor;
     },
     InputErrorKind::UnsupportedFeature},
    {"HeaderSizeBelow227", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<std::uint16_t>(b, las::field::headerSize, 226);
         return las::field::headerSize;
     },
     InputErrorKind::MalformedHeader},
    {"Las14HeaderSizeOf227", 4,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<std::uint16_t>(b, las::field::headerSize, 227);
         return las::field::headerSize;
     },
     InputErrorKind::MalformedHeader},
    {"UnknownPointFormat11", 4,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b[las::field::pointFormat] = 11;
         return las::field::pointFormat;
     },
     InputErrorKind::MalformedHeader},
    // A LAZ compression bit needs the laszip record that says how.
    {"LazCompressionBit7WithoutLaszipRecord", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b[las::field::pointFormat] |= 0x80;
         return las::field::pointFormat;
     },
     InputErrorKind::MalformedHeader},
    {"LazCompressionBit6WithoutLaszipRecord", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         b[las::field::pointFormat] |= 0x40;
         return las::field::pointFormat;
     },
     InputErrorKind::MalformedHeader},
    // A laszip record too short to be one: the LAZ reader names its payload.
    {"LaszipVariableLengthRecordTooShort", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         std::memcpy(&b[227 + 2], "laszip encoded\0\0", 16);
         put<std::uint16_t>(b, 227 + 18, las::kLaszipRecordId);
         return 227 + las::kVlrHeaderSize;
     },
     InputErrorKind::MalformedHeader},
    {"RecordLengthShorterThanFormat3", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<std::uint16_t>(b, las::field::recordLength, 33);
         return las::field::recordLength;
     },
     InputErrorKind::MalformedHeader},
    {"PointDataOffsetBeyondTheFile", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<std::uint32_t>(b, las::field::pointDataOffset,
                            static_cast<std::uint32_t>(b.size() + 1));
         return las::field::pointDataOffset;
     },
     InputErrorKind::MalformedHeader},
    {"PointDataOffsetInsideTheHeader", 4,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<std::uint32_t>(b, las::field::pointDataOffset, 300);
         return las::field::pointDataOffset;
     },
     InputErrorKind::MalformedHeader},
    {"ZeroXScale", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<double>(b, las::field::scale, 0.0);
         return las::field::scale;
     },
     InputErrorKind::MalformedHeader},
    {"NaNZScale", 4,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<double>(b, las::field::scale + 16, std::numeric_limits<double>::quiet_NaN());
         return las::field::scale + 16;
     },
     InputErrorKind::MalformedHeader},
    {"InfiniteYOffset", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<double>(b, las::field::offset + 8, std::numeric_limits<double>::infinity());
         return las::field::offset + 8;
     },
     InputErrorKind::MalformedHeader},
    {"ZeroPointCount", 2,
     [](std::vector<std::uint8_t>& b) -> std::uint64_t {
         put<std::uint32_t>(b, las::field::legacyPointCount, 0);
         return las::field::legacyPointCount;
     },
     InputErrorKind::NoPoints},
    {"Las14BothCountsZero", 4,
     [](std::vector<std::uint8_t>& b) -> std::
                                          uint64_t {
                                              put<std::uint32_t>(b, las::field::legacyPointCount,
                                                                 0);
                                              put<std::uint64_t>(b, las::field::pointCount, 0);
                                              return las::field::pointCount;
                                          },
     InputErrorKind::NoPoints},
    {"Las14CountsDisagree", 4,
     [](std::vector<std::uint8_t>& b) -> std::
                                          uint64_t {
                                              put<std::uint64_t>(b, las::field::pointCount,
                                                                 kRecords - 1);
                                              return las::field::pointCount;
                                          },
     InputErrorKind::CountMismatch},
    {"FileEndsInsideTheLastRecord", 2,
     [](std::vector<std::uint8_t>& b) -> std::
                                          uint64_t {
                                              b.resize(b.size() - 10);
                                              return 291 + (kRecords - 1) * kRecordLength;
                                          },
     InputErrorKind::Truncated},
    {"CountDeclaresOneRecordMore", 2,
     [](std::vector<std::uint8_t>& b) -> std::
                                          uint64_t {
                                              put<std::uint32_t>(b, las::field::legacyPointCount,
                                                                 kRecords + 1);
                                              return 291 + kRecords * kRecordLength;
                                          },
     InputErrorKind::Truncated},
    {"Las14CountNear2To64", 4,
     [](std::vector<std::uint8_t>& b) -> std::
                                          uint64_t {
                                              put<std::uint32_t>(b, las::field::legacyPointCount,
                                                                 0);
                                              put<std::uint64_t>(b, las::field::pointCount,
                                                                 std::uint64_t{1} << 62);
                                              return 439 + kRecords * kRecordLength;
                                          },
     InputErrorKind::Truncated},
    {"HeaderBoundsMissEveryPoint", 2,
     [](std::vector<std::uint8_t>& b)
         -> std::
             uint64_t {
                 // Both x bounds moved 1000 units east: the first record is already outside.
                 put<double>(b, las::field::bounds, get<double>(b, las::field::bounds) + 1000.0);
                 put<double>(b, las::field::bounds + 8,
                             get<double>(b, las::field::bounds + 8) + 1000.0);
                 return 291;
             },
     InputErrorKind::OutOfBounds},
};

class LasMalformedTest : public ::testing::TestWithParam<Corruption> {};

TEST_P(LasMalformedTest, FailsWithItsKindNamingFileAndByte) {
    const Corruption& c = GetParam();
    test::TempDir dir;
    const std::string path = dir.file(std::string(c.name) + ".las");
    std::vector<std::uint8_t> bytes =
        writeValidLas(path, c.versionMinor, 3, kRecords,
                      {{"omicron", 1, "ten bytes", std::vector<std::uint8_t>(10, 1)}});
    ASSERT_EQ(pointDataOffset(bytes), c.versionMinor == 4 ? 439u : 291u);
    const std::uint64_t byte = c.corrupt(bytes);
    test::writeBytes(path, bytes);
    expectInputError([&] { readAll(path); }, c.kind, path, byte);
}

INSTANTIATE_TEST_SUITE_P(LasCorruptions, LasMalformedTest, ::testing::ValuesIn(kCorruptions),
                         [](const ::testing::TestParamInfo<Corruption>& info) {
                             return std::string(info.param.name);
                         });

TEST(LasReaderTest, FileThatIsNotLasNamesTheSignatureItFound) {
    test::TempDir dir;
    const std::string path = dir.file("text.las");
    test::writeText(path, "ply\nformat ascii 1.0\n");
    expectInputError([&] { openLasReader(path, {}); }, InputErrorKind::MalformedHeader, path, 0);
    try {
        openLasReader(path, {});
    } catch (const InputError& error) {
        EXPECT_NE(error.detail().find("expected the LAS signature 'LASF', found 'ply\\x0a'"),
                  std::string::npos)
            << error.what();
    }
}

} // namespace
} // namespace omicron
