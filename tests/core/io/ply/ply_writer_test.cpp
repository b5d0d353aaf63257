// PLY writer: every encoding with every attribute combination, read back by the PLY reader
// and checked against the bytes in the file; the header it writes; atomic replacement.
#include "io/ply/ply_reader.hpp"
#include "io/ply/ply_writer.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace omicron {
namespace {

const CubeTransform kCube{{635000.5, 848000.25, 100.0}, 1000.0};
const glm::dvec3 kOffset{635000.0, 848000.0, 0.0};

PointBatch makeBatch(AttributeSet attributes, std::size_t count) {
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    PointBatch batch;
    batch.attributes = attributes;
    for (std::size_t i = 0; i < count; ++i) {
        batch.positions.emplace_back(unit(random), unit(random), 0.5f * unit(random));
        if (attributes.has(Attribute::Normal)) {
            batch.normals.emplace_back(unit(random) - 0.5f, unit(random) - 0.5f, 0.25f);
        }
        if (attributes.has(Attribute::Color)) {
            batch.colors.emplace_back(i % 256, (7 * i) % 256, 255 - i % 256);
        }
        if (attributes.has(Attribute::Intensity)) {
            batch.intensities.push_back(static_cast<std::uint16_t>(i * 131 % 65536));
        }
    }
    // The corners, so that the read-back cube equals kCube's span on x.
    batch.positions[0] = glm::vec3(0.0f);
    batch.positions[1] = glm::vec3(1.0f, 0.5f, 0.5f);
    return batch;
}

glm::vec3 expectedStored(const glm::vec3& unit) {
    return glm::vec3(kCube.toSource(unit) - kOffset);
}

// The x y z floats of every record, decoded here from the file's bytes or text.
std::vector<glm::vec3> storedPositions(const std::string& path, PlyEncoding encoding,
                                       std::size_t recordBytes, std::size_t count) {
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::string marker = "end_header\n";
    const auto at = std::search(bytes.begin(), bytes.end(), marker.begin(), marker.end());
    EXPECT_NE(at, bytes.end());
    const std::size_t body = static_cast<std::size_t>(at - bytes.begin()) + marker.size();
    std::vector<glm::vec3> positions;
    if (encoding == PlyEncoding::Ascii) {
        std::istringstream lines(
            std::string(bytes.begin() + static_cast<std::ptrdiff_t>(body), bytes.end()));
        std::string line;
        while (std::getline(lines, line)) {
            glm::vec3 p;
            const char* cursor = line.data();
            const char* end = line.data() + line.size();
            for (int axis = 0; axis < 3; ++axis) {
                const auto result = std::from_chars(cursor, end, p[axis]);
                EXPECT_EQ(result.ec, std::errc()) << line;
                cursor = result.ptr + 1;
            }
            positions.push_back(p);
        }
        return positions;
    }
    EXPECT_EQ(bytes.size(), body + count * recordBytes);
    for (std::size_t i = 0; i < count; ++i) {
        glm::vec3 p;
        for (int axis = 0; axis < 3; ++axis) {
            std::array<std::uint8_t, 4> raw;
            std::memcpy(raw.data(), bytes.data() + body + i * recordBytes + 4 * axis, 4);
            if (encoding == PlyEncoding::BinaryBigEndian) {
                std::reverse(raw.begin(), raw.end());
            }
            p[axis] = std::bit_cast<float>(raw);
        }
        positions.push_back(p);
    }
    return positions;
}

struct RoundTrip {
    PlyEncoding encoding;
    AttributeSet attributes;
    const char* name;
};

class PlyWriterRoundTrip : public testing::TestWithParam<RoundTrip> {};

TEST_P(PlyWriterRoundTrip, ReadsBackWhatWasWritten) {
    const RoundTrip& param = GetParam();
    test::TempDir dir;
    const std::string path = dir.file("cloud.ply");
    const PointBatch batch = makeBatch(param.attributes, 777);
    PlyWriteOptions options;
    options.encoding = param.encoding;
    options.offset = kOffset;
    options.comments = {"written by ply_writer_test"};
    writePly(path, batch, kCube, options);

    const std::size_t recordBytes = 12 + (param.attributes.has(Attribute::Normal) ? 12 : 0) +
                                    (param.attributes.has(Attribute::Color) ? 3 : 0) +
                                    (param.attributes.has(Attribute::Intensity) ? 2 : 0);
    const std::vector<glm::vec3> stored =
        storedPositions(path, param.encoding, recordBytes, batch.size());
    ASSERT_EQ(stored.size(), batch.size());
    for (std::size_t i = 0; i < batch.size(); ++i) {
        ASSERT_EQ(stored[i], expectedStored(batch.positions[i])) << "point " << i;
    }

    auto reader = openPlyReader(path, {});
    const CloudInfo& info = reader->info();
    EXPECT_EQ(info.pointCount, batch.size());
    EXPECT_EQ(info.attributes, param.attributes);
    EXPECT_EQ(info.sourceOffset, kOffset);
    PointBatch read;
    const ReadSummary summary = reader->read([&](const PointBatch& part) {
        read.positions.insert(read.positions.end(), part.positions.begin(), part.positions.end());
        read.normals.insert(read.normals.end(), part.normals.begin(), part.normals.end());
        read.colors.insert(read.colors.end(), part.colors.begin(), part.colors.end());
        read.intensities.insert(read.intensities.end(), part.intensities.begin(),
                                part.intensities.end());
    });
    EXPECT_EQ(summary.pointsDelivered, batch.size());
    ASSERT_EQ(read.positions.size(), batch.size());
    const double tolerance = info.cube.edge * 1.2e-7;
    for (std::size_t i = 0; i < batch.size(); ++i) {
        const glm::dvec3 expected = glm::dvec3(stored[i]) + kOffset;
        const glm::dvec3 actual = info.cube.toSource(read.positions[i]);
        ASSERT_NEAR(actual.x, expected.x, tolerance) << "point " << i;
        ASSERT_NEAR(actual.y, expected.y, tolerance) << "point " << i;
        ASSERT_NEAR(actual.z, expected.z, tolerance) << "point " << i;
    }
    EXPECT_EQ(read.normals, batch.normals);
    EXPECT_EQ(read.colors, batch.colors);
    EXPECT_EQ(read.intensities, batch.intensities);
}

const RoundTrip kRoundTrips[] = {
    {PlyEncoding::Ascii, AttributeSet(), "AsciiPositions"},
    {PlyEncoding::Ascii, AttributeSet(Attribute::Normal), "AsciiNormals"},
    {PlyEncoding::Ascii, AttributeSet(Attribute::Color), "AsciiColors"},
    {PlyEncoding::Ascii, AttributeSet(Attribute::Intensity), "AsciiIntensity"},
    {PlyEncoding::Ascii, AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity,
     "AsciiAll"},
    {PlyEncoding::BinaryLittleEndian, AttributeSet(), "LittleEndianPositions"},
    {PlyEncoding::BinaryLittleEndian, AttributeSet(Attribute::Normal), "LittleEndianNormals"},
    {PlyEncoding::BinaryLittleEndian, AttributeSet(Attribute::Color), "LittleEndianColors"},
    {PlyEncoding::BinaryLittleEndian, AttributeSet(Attribute::Intensity), "LittleEndianIntensity"},
    {PlyEncoding::BinaryLittleEndian, AttributeSet(Attribute::Normal) | Attribute::Color,
     "LittleEndianNormalsColors"},
    {PlyEncoding::BinaryLittleEndian,
     AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity, "LittleEndianAll"},
    {PlyEncoding::BinaryBigEndian, AttributeSet(), "BigEndianPositions"},
    {PlyEncoding::BinaryBigEndian, AttributeSet(Attribute::Normal), "BigEndianNormals"},
    {PlyEncoding::BinaryBigEndian, AttributeSet(Attribute::Color), "BigEndianColors"},
    {PlyEncoding::BinaryBigEndian, AttributeSet(Attribute::Intensity), "BigEndianIntensity"},
    {PlyEncoding::BinaryBigEndian,
     AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity, "BigEndianAll"},
};

INSTANTIATE_TEST_SUITE_P(Ply, PlyWriterRoundTrip, testing::ValuesIn(kRoundTrips),
                         [](const testing::TestParamInfo<RoundTrip>& info) {
                             return std::string(info.param.name);
                         });

std::string headerOf(const std::string& path) {
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::string text(bytes.begin(), bytes.end());
    return text.substr(0, text.find("end_header\n") + 11);
}

TEST(PlyWriter, HeaderListsOffsetCommentsAndProperties) {
    test::TempDir dir;
    const std::string path = dir.file("header.ply");
    PlyWriteOptions options;
    options.offset = {589000.0, 231000.5, 0.0};
    options.comments = {"source: a test", "two\nlines"};
    writePly(
        path,
        makeBatch(AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity, 3),
        kCube, options);
    EXPECT_EQ(headerOf(path), "ply\n"
                              "format binary_little_endian 1.0\n"
                              "comment offset 589000 231000.5 0\n"
                              "comment source: a test\n"
                              "comment two lines\n"
                              "element vertex 3\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "property float nx\nproperty float ny\nproperty float nz\n"
                              "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                              "property ushort intensity\n"
                              "end_header\n");
}

TEST(PlyWriter, NoOffsetCommentWithoutOffset) {
    test::TempDir dir;
    const std::string path = dir.file("plain.ply");
    PlyWriteOptions options;
    options.encoding = PlyEncoding::Ascii;
    PointBatch batch;
    batch.positions = {glm::vec3(0.1f, 0.25f, 1.0f)};
    writePly(path, batch, CubeTransform{{0, 0, 0}, 1.0}, options);
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    EXPECT_EQ(std::string(bytes.begin(), bytes.end()),
              "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n0.1 0.25 1\n");
}

TEST(PlyWriter, OffsetRoundTripsExactly) {
    test::TempDir dir;
    const std::string path = dir.file("offset.ply");
    PlyWriteOptions options;
    options.offset = {0.1, 1e7 / 3.0, -2.5e-3};
    writePly(path, makeBatch(AttributeSet(), 10), kCube, options);
    EXPECT_EQ(openPlyReader(path, {})->info().sourceOffset, options.offset);
}

TEST(PlyWriter, ReplacesAnExistingFileAndLeavesNoTemporary) {
    test::TempDir dir;
    const std::string path = dir.file("replace.ply");
    test::writeText(path, "old contents");
    writePly(path, makeBatch(AttributeSet(), 5), kCube);
    EXPECT_EQ(openPlyReader(path, {})->info().pointCount, 5u);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
        ++files;
    }
    EXPECT_EQ(files, 1u);
}

TEST(PlyWriter, MissingFolderThrowsOutputErrorAndCreatesNothing) {
    test::TempDir dir;
    const std::string path = dir.file("absent/cloud.ply");
    try {
        writePly(path, makeBatch(AttributeSet(), 5), kCube);
        ADD_FAILURE() << "expected OutputError";
    } catch (const OutputError& error) {
        EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path));
}

// Streamed in uneven pieces, the file is byte for byte the one writePly makes of the whole.
TEST(PlyStreamWriterTest, PiecesGiveTheSameFileAsOneBatch) {
    for (PlyEncoding encoding : {PlyEncoding::Ascii, PlyEncoding::BinaryBigEndian}) {
        const AttributeSet attributes =
            AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity;
        const PointBatch batch = makeBatch(attributes, 5000);
        test::TempDir dir;
        PlyWriteOptions options;
        options.encoding = encoding;
        options.offset = kOffset;
        writePly(dir.file("whole.ply"), batch, kCube, options);
        PlyStreamWriter writer(dir.file("pieces.ply"), batch.size(), attributes, options);
        for (const auto& [first, last] : {std::pair{0, 1}, std::pair{1, 1}, std::pair{1, 5000}}) {
            PointBatch piece;
            piece.attributes = attributes;
            for (int i = first; i < last; ++i) {
                piece.positions.push_back(batch.positions[i]);
                piece.normals.push_back(batch.normals[i]);
                piece.colors.push_back(batch.colors[i]);
                piece.intensities.push_back(batch.intensities[i]);
            }
            writer.append(piece, kCube);
        }
        writer.finish();
        EXPECT_EQ(test::readBytes(dir.file("whole.ply")), test::readBytes(dir.file("pieces.ply")));
    }
}

TEST(PlyStreamWriterTest, AWrongCountOrAttributeSetFailsAndLeavesNoFile) {
    const PointBatch batch = makeBatch(AttributeSet(Attribute::Color), 10);
    test::TempDir dir;
    const std::string path = dir.file("out.ply");
    {
        PlyStreamWriter writer(path, 11, batch.attributes);
        writer.append(batch, kCube);
        try {
            writer.finish();
            FAIL() << "finish() accepted 10 of 11 points";
        } catch (const OutputError& error) {
            EXPECT_EQ(std::string(error.what()),
                      path + ": only 10 points appended, but the header declares 11");
        }
    }
    {
        PlyStreamWriter writer(path, 15, batch.attributes);
        writer.append(batch, kCube);
        EXPECT_THROW(writer.append(batch, kCube), OutputError); // 20 > 15
    }
    {
        PlyStreamWriter writer(path, 10, AttributeSet(Attribute::Intensity));
        EXPECT_THROW(writer.append(batch, kCube), OutputError);
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

} // namespace
} // namespace omicron
