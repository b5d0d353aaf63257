// PLY reader: every real cloud of ../shared/data against its README, hand-made files for each
// layout rule (element order, lists, types, endianness, line endings), the streaming contract
// (batches, cancellation, known bounds, non-finite points) and one test per malformed input.
#include "io/input_error.hpp"
#include "io/ply/ply_reader.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <limits>
#include <string>
#include <vector>

namespace omicron {
namespace {

struct ReadResult {
    CloudInfo info;
    PointBatch points;
    ReadSummary summary;
    std::vector<std::size_t> batchSizes;
};

ReadResult readAll(const std::string& path, const OpenOptions& openOptions = {},
                   const ReadOptions& readOptions = {}) {
    ReadResult result;
    auto reader = openPlyReader(path, openOptions);
    result.info = reader->info();
    result.points.attributes = result.info.attributes;
    result.summary = reader->read(
        [&](const PointBatch& batch) {
            EXPECT_TRUE(batch.consistent());
            EXPECT_EQ(batch.attributes, result.info.attributes);
            result.batchSizes.push_back(batch.size());
            PointBatch& all = result.points;
            all.positions.insert(all.positions.end(), batch.positions.begin(),
                                 batch.positions.end());
            all.normals.insert(all.normals.end(), batch.normals.begin(), batch.normals.end());
            all.colors.insert(all.colors.end(), batch.colors.begin(), batch.colors.end());
            all.intensities.insert(all.intensities.end(), batch.intensities.begin(),
                                   batch.intensities.end());
        },
        readOptions);
    return result;
}

// Runs `action`, which must throw InputError of `kind` whose message names `path` and holds
// `where` (e.g. "byte 123: " or just "line "). Returns the message for further checks.
template <typename Action>
std::string expectInputError(Action&& action, InputErrorKind kind, const std::string& path,
                             const std::string& where) {
    try {
        action();
    } catch (const InputError& error) {
        const std::string message = error.what();
        EXPECT_EQ(error.kind(), kind) << "got '" << toString(error.kind()) << "': " << message;
        EXPECT_NE(message.find(path), std::string::npos) << message;
        EXPECT_NE(message.find(where), std::string::npos)
            << "expected '" << where << "' in: " << message;
        return message;
    }
    ADD_FAILURE() << "expected an InputError (" << toString(kind) << ") for " << path;
    return {};
}

std::string expectOpenError(const std::string& path, InputErrorKind kind,
                            const std::string& where) {
    return expectInputError([&] { openPlyReader(path, {}); }, kind, path, where);
}

std::string expectReadError(const std::string& path, InputErrorKind kind, const std::string& where,
                            const OpenOptions& options = {}) {
    return expectInputError([&] { readAll(path, options); }, kind, path, where);
}

// Builds a PLY file: a header, then binary values in either byte order or ascii text.
class PlyBytes {
public:
    explicit PlyBytes(const std::string& header, bool bigEndian = false)
        : m_bytes(header.begin(), header.end()), m_bigEndian(bigEndian) {}

    std::size_t size() const { return m_bytes.size(); }

    template <typename T> PlyBytes& put(T value) {
        auto raw = std::bit_cast<std::array<std::uint8_t, sizeof(T)>>(value);
        if (m_bigEndian) {
            std::reverse(raw.begin(), raw.end());
        }
        m_bytes.insert(m_bytes.end(), raw.begin(), raw.end());
        return *this;
    }
    PlyBytes& text(const std::string& text) {
        m_bytes.insert(m_bytes.end(), text.begin(), text.end());
        return *this;
    }
    void write(const std::string& path) const { test::writeBytes(path, m_bytes); }

private:
    std::vector<std::uint8_t> m_bytes;
    bool m_bigEndian;
};

// A vertex property that makes records variable-size, so that the general code reads them.
const std::string kEmptyList = "property list uchar int unused\n";

std::string binaryHeader(std::size_t vertices,
                         const std::string& properties = "property float x\n"
                                                         "property float y\n"
                                                         "property float z\n",
                         const std::string& format = "binary_little_endian") {
    return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) + "\n" +
           properties + "end_header\n";
}

glm::dvec3 sourceOf(const ReadResult& result, std::size_t index) {
    return result.info.cube.toSource(result.points.positions[index]);
}

// Float rounding of a unit-cube coordinate, in source units.
double unitTolerance(const ReadResult& result) {
    return result.info.cube.edge * 1.2e-7;
}

void expectNear(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance) {
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

// ---- the real clouds ---------------------------------------------------------------------

struct SharedCloud {
    const char* file;
    std::uint64_t points;
    bool normals;
    bool colors;
    glm::dvec3 offset;
    glm::dvec3 min; // README bounds in source units (offset added)
    glm::dvec3 max;
    double boundsTolerance; // half the last printed digit of the README, plus float rounding
};

const SharedCloud kSharedClouds[] = {
    {"bunny.ply",
     35947,
     true,
     false,
     {0, 0, 0},
     {-0.0947, 0.0330, -0.0619},
     {0.0610, 0.1873, 0.0588},
     6e-5},
    {"autzen_trim.ply",
     110000,
     false,
     true,
     {635000, 848000, 0},
     {636001.76, 848935.20, 406.26},
     {637179.22, 849497.90, 520.51},
     6e-3},
    {"autzen_south.ply",
     4844261,
     false,
     true,
     {635000, 848000, 0},
     {635577.79, 848882.15, 406.14},
     {638923.87, 850999.99, 615.26},
     6e-3},
    {"dragon.ply",
     437645,
     true,
     false,
     {0, 0, 0},
     {-0.1083, 0.0527, -0.0504},
     {0.0966, 0.1972, 0.0412},
     6e-5},
    {"indoor.ply",
     808042,
     false,
     false,
     {0, 0, 0},
     {-22.99, -1.97, -7.90},
     {5.63, 7.55, 12.36},
     6e-3},
    {"lion.ply",
     341989,
     true,
     true,
     {0, 0, 0},
     {-4.9850, 1.0390, -3.4450},
     {-0.7890, 6.7235, 1.1235},
     6e-4},
    {"sorvilier.ply",
     498868,
     false,
     true,
     {589000, 231000, 0},
     {589500.00, 231300.00, 722.555},
     {590099.99, 231565.70, 789.905},
     6e-3},
};

// The first record's bytes, found independently of the reader: after "end_header\n".
std::vector<std::uint8_t> firstRecordBytes(const std::string& path, std::size_t count) {
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    const std::string marker = "end_header\n";
    const auto at = std::search(bytes.begin(), bytes.end(), marker.begin(), marker.end());
    EXPECT_NE(at, bytes.end());
    const auto start = at + static_cast<std::ptrdiff_t>(marker.size());
    return {start, start + static_cast<std::ptrdiff_t>(count)};
}

float floatAt(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
    float value;
    std::memcpy(&value, bytes.data() + offset, sizeof value);
    return value;
}

class PlySharedData : public testing::TestWithParam<SharedCloud> {};

TEST_P(PlySharedData, MatchesReadme) {
    const SharedCloud& cloud = GetParam();
    OMICRON_REQUIRE_SHARED_FILE(path, cloud.file);
    const ReadResult result = readAll(path);

    EXPECT_EQ(result.info.format, CloudFormat::PlyBinaryLittleEndian);
    EXPECT_EQ(result.info.pointCount, cloud.points);
    EXPECT_EQ(result.summary.pointsDelivered, cloud.points);
    EXPECT_EQ(result.summary.skippedNonFinite, 0u);
    EXPECT_FALSE(result.summary.cancelled);
    EXPECT_FALSE(result.info.boundsFromHeader);
    EXPECT_EQ(result.info.attributes.has(Attribute::Normal), cloud.normals);
    EXPECT_EQ(result.info.attributes.has(Attribute::Color), cloud.colors);
    EXPECT_FALSE(result.info.attributes.has(Attribute::Intensity));
    EXPECT_TRUE(result.points.consistent());
    EXPECT_EQ(result.points.size(), cloud.points);
    EXPECT_EQ(result.info.sourceOffset, cloud.offset);

    const std::size_t recordBytes = 12 + (cloud.normals ? 12 : 0) + (cloud.colors ? 3 : 0);
    EXPECT_EQ(result.info.formatDetail, "PLY binary_little_endian 1.0, " +
                                            std::to_string(cloud.points) + " vertices, " +
                                            std::to_string(recordBytes) + "-byte records");
    expectNear(result.info.sourceBounds.min, cloud.min, cloud.boundsTolerance);
    expectNear(result.info.sourceBounds.max, cloud.max, cloud.boundsTolerance);
    EXPECT_EQ(result.info.cube, CubeTransform::fromBounds(result.info.sourceBounds));

    // Every position in the unit cube, and the cube's min corner reached on every axis.
    glm::vec3 low(std::numeric_limits<float>::infinity());
    glm::vec3 high(-std::numeric_limits<float>::infinity());
    for (const glm::vec3& p : result.points.positions) {
        low = glm::min(low, p);
        high = glm::max(high, p);
    }
    EXPECT_EQ(low, glm::vec3(0.0f));
    EXPECT_LE(std::max({high.x, high.y, high.z}), 1.0f);
    EXPECT_EQ(std::max({high.x, high.y, high.z}), 1.0f);

    // The first record, decoded here from the file's bytes.
    const std::vector<std::uint8_t> first = firstRecordBytes(path, recordBytes);
    const glm::dvec3 stored(floatAt(first, 0), floatAt(first, 4), floatAt(first, 8));
    expectNear(sourceOf(result, 0), stored + cloud.offset, unitTolerance(result));
    if (cloud.normals) {
        EXPECT_EQ(result.points.normals[0],
                  glm::vec3(floatAt(first, 12), floatAt(first, 16), floatAt(first, 20)));
    }
    if (cloud.colors) {
        const std::size_t at = cloud.normals ? 24 : 12;
        EXPECT_EQ(result.points.colors[0], glm::u8vec3(first[at], first[at + 1], first[at + 2]));
    }
}

INSTANTIATE_TEST_SUITE_P(Ply, PlySharedData, testing::ValuesIn(kSharedClouds),
                         [](const testing::TestParamInfo<SharedCloud>& info) {
                             std::string name = info.param.file;
                             name = name.substr(0, name.find('.'));
                             name.erase(std::remove(name.begin(), name.end(), '_'), name.end());
                             return name;
                         });

TEST(PlyReaderSharedData, BunnyHas1113ZeroNormals) {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    const ReadResult result = readAll(path);
    const auto zero =
        std::count(result.points.normals.begin(), result.points.normals.end(), glm::vec3(0.0f));
    EXPECT_EQ(zero, 1113);
    for (const glm::vec3& normal : result.points.normals) {
        const float length =
            std::sqrt(normal.x * normal.x + normal.y * normal.y + normal.z * normal.z);
        EXPECT_TRUE(length == 0.0f || std::abs(length - 1.0f) < 1e-4f) << length;
    }
}

TEST(PlyReaderSharedData, BatchSizeIsRespected) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.ply");
    ReadOptions options;
    options.batchPoints = 1000;
    const ReadResult result = readAll(path, {}, options);
    EXPECT_EQ(result.summary.batches, 110u); // 110000 / 1000
    EXPECT_EQ(result.batchSizes.size(), 110u);
    for (const std::size_t size : result.batchSizes) {
        EXPECT_EQ(size, 1000u);
    }
    options.batchPoints = 7000;
    const ReadResult uneven = readAll(path, {}, options);
    EXPECT_EQ(uneven.summary.batches, 16u); // ceil(110000 / 7000)
    EXPECT_EQ(uneven.batchSizes.back(), 110000u - 15u * 7000u);
    EXPECT_EQ(uneven.points.positions, result.points.positions);
}

TEST(PlyReaderSharedData, KnownBoundsGiveTheSamePoints) {
    OMICRON_REQUIRE_SHARED_FILE(path, "sorvilier.ply");
    const ReadResult first = readAll(path);
    OpenOptions options;
    options.knownBounds = first.info.sourceBounds;
    const ReadResult second = readAll(path, options);
    EXPECT_EQ(second.info.cube, first.info.cube);
    EXPECT_EQ(second.points.positions, first.points.positions);
    EXPECT_EQ(second.points.colors, first.points.colors);
}

// ---- layouts -----------------------------------------------------------------------------

TEST(PlyReaderLayout, AsciiWithOffsetComment) {
    test::TempDir dir;
    const std::string path = dir.file("offset.ply");
    test::writeText(path, "ply\nformat ascii 1.0\n"
                          "comment offset 1000 2000 -5 (add to x y z; units: metres)\n"
                          "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "end_header\n"
                          "1.5 2.5 3.5\n"
                          "-1 0 10\n"
                          "+4 1e1 0.25\n");
    const ReadResult result = readAll(path);
    EXPECT_EQ(result.info.format, CloudFormat::PlyAscii);
    EXPECT_EQ(result.info.formatDetail, "PLY ascii 1.0, 3 vertices");
    EXPECT_EQ(result.info.sourceOffset, glm::dvec3(1000, 2000, -5));
    EXPECT_EQ(result.info.sourceBounds.min, glm::dvec3(999, 2000, -4.75));
    EXPECT_EQ(result.info.sourceBounds.max, glm::dvec3(1004, 2010, 5));
    ASSERT_EQ(result.points.size(), 3u);
    expectNear(sourceOf(result, 0), {1001.5, 2002.5, -1.5}, unitTolerance(result));
    expectNear(sourceOf(result, 2), {1004, 2010, -4.75}, unitTolerance(result));
}

TEST(PlyReaderLayout, VertexAfterFixedSizeElementIsFound) {
    test::TempDir dir;
    const std::string path = dir.file("camera_first.ply");
    PlyBytes bytes("ply\nformat binary_little_endian 1.0\nelement camera 2\nproperty double fov\n"
                   "property uchar id\nelement vertex 2\nproperty float x\nproperty float y\n"
                   "property float z\nend_header\n");
    bytes.put(1.0).put(std::uint8_t{1}).put(2.0).put(std::uint8_t{2});
    bytes.put(1.0f).put(2.0f).put(3.0f).put(4.0f).put(6.0f).put(8.0f);
    bytes.write(path);
    const ReadResult result = readAll(path);
    ASSERT_EQ(result.points.size(), 2u);
    expectNear(sourceOf(result, 0), {1, 2, 3}, 1e-6);
    expectNear(sourceOf(result, 1), {4, 6, 8}, 1e-6);
}

TEST(PlyReaderLayout, FacesBeforeVerticesAreSkippedBinary) {
    test::TempDir dir;
    const std::string path = dir.file("faces_first.ply");
    PlyBytes bytes("ply\nformat binary_little_endian 1.0\nelement face 3\n"
                   "property list uchar int vertex_indices\nproperty uchar flags\n"
                   "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n");
    bytes.put(std::uint8_t{3}).put(0).put(1).put(0).put(std::uint8_t{9});
    bytes.put(std::uint8_t{0}).put(std::uint8_t{9});
    bytes.put(std::uint8_t{4}).put(0).put(1).put(1).put(0).put(std::uint8_t{9});
    bytes.put(-1.0f).put(0.0f).put(0.5f).put(1.0f).put(2.0f).put(0.5f);
    bytes.write(path);
    const ReadResult result = readAll(path);
    ASSERT_EQ(result.points.size(), 2u);
    expectNear(sourceOf(result, 0), {-1, 0, 0.5}, 1e-6);
    expectNear(sourceOf(result, 1), {1, 2, 0.5}, 1e-6);
}

TEST(PlyReaderLayout, FacesAfterVerticesAreIgnoredBinary) {
    test::TempDir dir;
    const std::string path = dir.file("faces_after.ply");
    PlyBytes bytes("ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 1\n"
                   "property list uchar int vertex_indices\nend_header\n");
    bytes.put(0.0f).put(0.0f).put(0.0f).put(1.0f).put(1.0f).put(1.0f);
    bytes.put(std::uint8_t{3}).put(0).put(1).put(1);
    bytes.write(path);
    const ReadResult result = readAll(path);
    EXPECT_EQ(result.points.size(), 2u);
}

TEST(PlyReaderLayout, FacesAroundVerticesAscii) {
    test::TempDir dir;
    const std::string path = dir.file("faces_ascii.ply");
    test::writeText(path, "ply\nformat ascii 1.0\nelement face 2\n"
                          "property list uchar int vertex_indices\nelement vertex 2\n"
                          "property float x\nproperty float y\nproperty float z\n"
                          "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                          "end_header\n"
                          "3 0 1 1\n"
                          "4 0 1 1 0\n"
                          "1 2 3\n"
                          "\n"
                          "4 5 6\n"
                          "0 1\n");
    const ReadResult result = readAll(path);
    ASSERT_EQ(result.points.size(), 2u);
    expectNear(sourceOf(result, 0), {1, 2, 3}, 1e-6);
    expectNear(sourceOf(result, 1), {4, 5, 6}, 1e-6);
}

TEST(PlyReaderLayout, ShuffledPropertiesOfEveryType) {
    test::TempDir dir;
    const std::string path = dir.file("shuffled.ply");
    PlyBytes bytes("ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
                   "property ushort green\nproperty double z\nproperty char junk\n"
                   "property float nz\nproperty int y\nproperty uint8 red\n"
                   "property float64 nx\nproperty short ny\nproperty uint intensity\n"
                   "property uint16 blue\nproperty float32 x\nend_header\n");
    for (int i = 0; i < 2; ++i) {
        bytes
            .put(std::uint16_t(i == 0 ? 65535 : 257 * 100 + 128)) // green
            .put(i == 0 ? 0.25 : -0.75)                           // z
            .put(std::int8_t{-3})                                 // junk
            .put(0.5f)                                            // nz
            .put(std::int32_t(i == 0 ? -7 : 12))                  // y
            .put(std::uint8_t(i == 0 ? 17 : 250))                 // red
            .put(-0.5)                                            // nx
            .put(std::int16_t{1})                                 // ny
            .put(std::uint32_t(i == 0 ? 70000 : 1234))            // intensity (clamped)
            .put(std::uint16_t(i == 0 ? 0 : 1000))                // blue
            .put(i == 0 ? 3.5f : -2.0f);                          // x
    }
    bytes.write(path);
    const ReadResult result = readAll(path);
    EXPECT_EQ(result.info.attributes,
              AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity);
    EXPECT_EQ(result.info.formatDetail,
              "PLY binary_little_endian 1.0, 2 vertices, 40-byte records");
    ASSERT_EQ(result.points.size(), 2u);
    expectNear(sourceOf(result, 0), {3.5, -7, 0.25}, 1e-5);
    expectNear(sourceOf(result, 1), {-2, 12, -0.75}, 1e-5);
    EXPECT_EQ(result.points.normals[0], glm::vec3(-0.5f, 1.0f, 0.5f));
    // red uchar as is; green and blue ushort scaled by 1/257 and rounded.
    EXPECT_EQ(result.points.colors[0], glm::u8vec3(17, 255, 0));
    EXPECT_EQ(result.points.colors[1], glm::u8vec3(250, 100, 4));
    EXPECT_EQ(result.points.intensities[0], 65535);
    EXPECT_EQ(result.points.intensities[1], 1234);
}

TEST(PlyReaderLayout, AttributeAliasesAndFloatColours) {
    test::TempDir dir;
    const std::string path = dir.file("aliases.ply");
    test::writeText(path, "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                          "property float y\nproperty float z\nproperty float normal_x\n"
                          "property float normal_y\nproperty float normal_z\nproperty float r\n"
                          "property float g\nproperty double b\nproperty float scalar_intensity\n"
                          "end_header\n"
                          "0 0 0 1 0 0 0.5 1.5 -0.2 12.4\n"
                          "1 1 1 0 1 0 1 0.1 0.998 -3\n");
    const ReadResult result = readAll(path);
    ASSERT_EQ(result.points.size(), 2u);
    EXPECT_EQ(result.points.normals[0], glm::vec3(1, 0, 0));
    EXPECT_EQ(result.points.colors[0], glm::u8vec3(128, 255, 0)); // 0.5 -> 127.5 rounds up
    EXPECT_EQ(result.points.colors[1], glm::u8vec3(255, 26, 254));
    EXPECT_EQ(result.points.intensities[0], 12);
    EXPECT_EQ(result.points.intensities[1], 0);
}

TEST(PlyReaderLayout, DiffuseColourNames) {
    test::TempDir dir;
    const std::string path = dir.file("diffuse.ply");
    test::writeText(path, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                          "property float y\nproperty float z\nproperty uchar diffuse_red\n"
                          "property uchar diffuse_green\nproperty uchar diffuse_blue\n"
                          "end_header\n1 2 3 10 20 30\n");
    const ReadResult result = readAll(path);
    EXPECT_EQ(result.info.attributes, AttributeSet(Attribute::Color));
    EXPECT_EQ(result.points.colors[0], glm::u8vec3(10, 20, 30));
}

TEST(PlyReaderLayout, ListsInsideTheVertexElement) {
    test::TempDir dir;
    const std::string binaryPath = dir.file("vertex_lists.ply");
    PlyBytes bytes("ply\nformat binary_big_endian 1.0\nelement vertex 3\n"
                   "property list uchar float tags\nproperty float x\nproperty float y\n"
                   "property list ushort int ids\nproperty float z\nend_header\n",
                   true);
    for (int i = 0; i < 3; ++i) {
        bytes.put(std::uint8_t(i)); // i tags
        for (int t = 0; t < i; ++t) {
            bytes.put(9.0f);
        }
        bytes.put(float(i)).put(float(2 * i)).put(std::uint16_t{1}).put(7).put(float(-i));
    }
    bytes.write(binaryPath);
    const ReadResult binary = readAll(binaryPath);
    EXPECT_EQ(binary.info.formatDetail,
              "PLY binary_big_endian 1.0, 3 vertices, variable-size records (lists)");
    ASSERT_EQ(binary.points.size(), 3u);
    for (int i = 0; i < 3; ++i) {
        expectNear(sourceOf(binary, i), {i, 2 * i, -i}, 1e-6);
    }

    const std::string asciiPath = dir.file("vertex_lists_ascii.ply");
    test::writeText(asciiPath, "ply\nformat ascii 1.0\nelement vertex 3\n"
                               "property list uchar float tags\nproperty float x\n"
                               "property float y\nproperty list ushort int ids\n"
                               "property float z\nend_header\n"
                               "0 0 0 1 7 0\n1 9 1 2 1 7 -1\n2 9 9 2 4 1 7 -2\n");
    const ReadResult ascii = readAll(asciiPath);
    EXPECT_EQ(ascii.points.positions, binary.points.positions);
}

TEST(PlyReaderLayout, BigEndianLittleEndianAndAsciiAgreeBitForBit) {
    // The binary files take the SIMD fast path (big-endian after a byte swap), ascii the general
    // one.
    test::TempDir dir;
    const float values[][6] = {{1.25f, -3.5f, 1e-3f, 0.0f, 0.6f, 0.8f},
                               {1000.1f, 7.0f, -0.0f, 1.0f, 0.0f, 0.0f},
                               {-17.75f, 3.0e4f, 42.0f, 0.0f, -1.0f, 0.0f},
                               {0.1f, 0.2f, 0.3f, 0.36f, 0.48f, 0.8f}};
    const std::string properties = "property float x\nproperty float y\nproperty float z\n"
                                   "property float nx\nproperty float ny\nproperty float nz\n"
                                   "property uchar red\nproperty uchar green\n"
                                   "property uchar blue\n";
    PlyBytes little(binaryHeader(4, properties, "binary_little_endian"));
    PlyBytes big(binaryHeader(4, properties, "binary_big_endian"), true);
    std::string ascii = "ply\nformat ascii 1.0\nelement vertex 4\n" + properties + "end_header\n";
    for (int i = 0; i < 4; ++i) {
        for (const float value : values[i]) {
            little.put(value);
            big.put(value);
            char text[32];
            std::snprintf(text, sizeof text, "%.9g ", value); // round-trips a float
            ascii += text;
        }
        for (int c = 0; c < 3; ++c) {
            little.put(std::uint8_t(40 * i + c));
            big.put(std::uint8_t(40 * i + c));
            ascii += std::to_string(40 * i + c) + (c == 2 ? "\r\n" : " ");
        }
    }
    little.write(dir.file("le.ply"));
    big.write(dir.file("be.ply"));
    test::writeText(dir.file("ascii.ply"), ascii);
    const ReadResult fromLittle = readAll(dir.file("le.ply"));
    const ReadResult fromBig = readAll(dir.file("be.ply"));
    const ReadResult fromAscii = readAll(dir.file("ascii.ply"));
    EXPECT_EQ(fromBig.info.format, CloudFormat::PlyBinaryBigEndian);
    for (const ReadResult* other : {&fromBig, &fromAscii}) {
        EXPECT_EQ(other->info.sourceBounds, fromLittle.info.sourceBounds);
        EXPECT_EQ(other->points.positions, fromLittle.points.positions);
        EXPECT_EQ(other->points.normals, fromLittle.points.normals);
        EXPECT_EQ(other->points.colors, fromLittle.points.colors);
    }
    for (int i = 0; i < 4; ++i) {
        expectNear(sourceOf(fromLittle, i), {values[i][0], values[i][1], values[i][2]},
                   unitTolerance(fromLittle));
        EXPECT_EQ(fromLittle.points.normals[i],
                  glm::vec3(values[i][3], values[i][4], values[i][5]));
    }
}

TEST(PlyReaderLayout, NonAdjacentFloatPositionsTakeTheScalarPath) {
    test::TempDir dir;
    const std::string path = dir.file("gaps.ply");
    PlyBytes bytes(binaryHeader(3,
                                "property float z\nproperty uchar red\nproperty float x\n"
                                "property uchar green\nproperty uchar blue\nproperty float y\n"));
    for (int i = 0; i < 3; ++i) {
        bytes.put(float(10 * i))
            .put(std::uint8_t(i))
            .put(float(i))
            .put(std::uint8_t(2 * i))
            .put(std::uint8_t(3 * i))
            .put(float(-i));
    }
    bytes.write(path);
    const ReadResult result = readAll(path);
    ASSERT_EQ(result.points.size(), 3u);
    for (int i = 0; i < 3; ++i) {
        expectNear(sourceOf(result, i), {i, -i, 10 * i}, 1e-5);
        EXPECT_EQ(result.points.colors[i], glm::u8vec3(i, 2 * i, 3 * i));
    }
}

// The fast loops' read of a file against the general code's read of the same values: the
// same bounds, cube, skipped points and attributes, bit for bit.
void expectTheSameRead(const ReadResult& fast, const ReadResult& general) {
    EXPECT_EQ(fast.summary.skippedNonFinite, general.summary.skippedNonFinite);
    EXPECT_EQ(fast.info.sourceBounds, general.info.sourceBounds);
    EXPECT_EQ(fast.info.cube, general.info.cube);
    EXPECT_EQ(fast.points.positions, general.points.positions);
    EXPECT_EQ(fast.points.normals, general.points.normals);
    EXPECT_EQ(fast.points.colors, general.points.colors);
    EXPECT_EQ(fast.points.intensities, general.points.intensities);
}

// The same vertices in three files: little- and big-endian fixed records (the fast loops, the
// big-endian ones after a byte swap) and little-endian records with an empty list
// (variable-size: the general code, value by value). `header(format, moreProperties)`.
class ThreeEncodings {
public:
    explicit ThreeEncodings(
        const std::function<std::string(const char*, const std::string&)>& header)
        : m_little(header("binary_little_endian", "")),
          m_big(header("binary_big_endian", ""), true),
          m_general(header("binary_little_endian", kEmptyList)) {}

    // put(bytes) writes one vertex's values into each.
    template <typename Put> void vertex(const Put& put) {
        for (PlyBytes* bytes : {&m_little, &m_big, &m_general}) {
            put(*bytes);
        }
        m_general.put(std::uint8_t(0));
    }

    // The little-endian read, after checking that the other two read the same.
    ReadResult readAll(const test::TempDir& dir) const {
        m_little.write(dir.file("le.ply"));
        m_big.write(dir.file("be.ply"));
        m_general.write(dir.file("general.ply"));
        ReadResult fast = omicron::readAll(dir.file("le.ply"));
        expectTheSameRead(fast, omicron::readAll(dir.file("general.ply")));
        expectTheSameRead(fast, omicron::readAll(dir.file("be.ply")));
        return fast;
    }

private:
    PlyBytes m_little, m_big, m_general;
};

// A ushort or float intensity (CloudCompare's "scalar_Intensity"), beside float positions and
// uchar colours, is read by the fast loops (and the bounds by the parallel pre-pass, over
// several 1 MiB blocks) exactly as the general code reads it from the same values (records
// with an empty list: variable-size, value by value); with adjacent x y z (SSE2) and apart
// (scalar); little-endian, and big-endian (byte-swapped in place, then the same loops; the
// points at the bounds go through the exact code, which must not swap them again).
TEST(PlyReaderLayout, IntensityOnTheFastPathAgreesWithTheGeneralOne) {
    struct Layout {
        const char* name;
        std::string properties;
        bool apart;
        bool floatIntensity;
    };
    const Layout layouts[] = {
        {"adjacent",
         "property float x\nproperty float y\nproperty float z\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         "property ushort intensity\nproperty float scalar_other\n",
         false, false},
        {"apart",
         "property ushort intensity\nproperty float z\nproperty uchar red\n"
         "property float x\nproperty uchar green\nproperty uchar blue\n"
         "property float y\nproperty float scalar_other\n",
         true, false},
        {"float",
         "property float x\nproperty float y\nproperty float z\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         "property float scalar_Intensity\nproperty float scalar_other\n",
         false, true},
    };
    constexpr std::size_t kPoints = 250'000; // 21- or 23-byte records: five pre-pass blocks
    for (const Layout& layout : layouts) {
        SCOPED_TRACE(layout.name);
        test::TempDir dir;
        ThreeEncodings files([&](const char* format, const std::string& more) {
            return binaryHeader(kPoints, layout.properties + more, format);
        });
        for (std::size_t i = 0; i < kPoints; ++i) {
            // A NaN point now and then: skipped and counted by both paths.
            const float x = i % 9973 == 5 ? std::numeric_limits<float>::quiet_NaN()
                                          : 1000.0f + 0.37f * static_cast<float>(i % 5000);
            const float y = -20.0f + 0.011f * static_cast<float>(i);
            const float z = 3.0f * std::sin(0.001f * static_cast<float>(i));
            const auto intensity = static_cast<std::uint16_t>((i * 7919) % 65536);
            // Fractions to round, negatives, NaN and values above 65535 to clamp.
            const float floatIntensity = i % 101 == 3 ? std::numeric_limits<float>::quiet_NaN()
                                                      : 0.37f * static_cast<float>(i) - 1000.0f;
            const auto rgb = glm::u8vec3(i % 256, (i / 256) % 256, (3 * i) % 256);
            files.vertex([&](PlyBytes& bytes) {
                if (layout.apart) {
                    bytes.put(intensity).put(z).put(rgb.r).put(x).put(rgb.g).put(rgb.b).put(y);
                } else {
                    bytes.put(x).put(y).put(z).put(rgb.r).put(rgb.g).put(rgb.b);
                    if (layout.floatIntensity) {
                        bytes.put(floatIntensity);
                    } else {
                        bytes.put(intensity);
                    }
                }
                bytes.put(float(i));
            });
        }
        const ReadResult fast = files.readAll(dir);
        ASSERT_TRUE(fast.info.attributes.has(Attribute::Intensity));
        EXPECT_EQ(fast.summary.skippedNonFinite, 26u); // i = 5, 9978, ... below 250,000
        ASSERT_EQ(fast.points.intensities.size(), kPoints - 26);
        if (layout.floatIntensity) {
            EXPECT_EQ(fast.points.intensities[3], 0);         // NaN
            EXPECT_EQ(fast.points.intensities[2703], 0);      // point 2704: 0.48
            EXPECT_EQ(fast.points.intensities[2705], 1);      // point 2706: 1.22
            EXPECT_EQ(fast.points.intensities[9000], 2330);   // point 9001: 2330.37
            EXPECT_EQ(fast.points.intensities.back(), 65535); // 91,499.63 clamped
        } else {
            EXPECT_EQ(fast.points.intensities[0], 0);
            EXPECT_EQ(fast.points.intensities[1], 7919);
            EXPECT_EQ(fast.points.intensities[9], (10 * 7919) % 65536); // point 5 was skipped
        }
    }
}

// Double x y z (PDAL's PLY writer), with a "comment offset", float normals, uchar colours and
// a ushort intensity: the double loops and the parallel pre-pass, little- and big-endian, give
// what the general code gives from the same values (records with an empty list), bit for bit,
// NaN points skipped and counted alike.
TEST(PlyReaderLayout, DoublePositionsOnTheFastPathAgreeWithTheGeneralOne) {
    const std::string properties =
        "property double x\nproperty double y\nproperty double z\nproperty float nx\n"
        "property float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
        "property uchar blue\nproperty ushort intensity\n";
    const auto header = [&](const char* format, const std::string& more) {
        return "ply\nformat " + std::string(format) +
               " 1.0\ncomment offset 635000 848000 0\nelement vertex 150000\n" + properties + more +
               "end_header\n";
    };
    constexpr std::size_t kPoints = 150'000; // 45-byte records: 6.75 MB, seven pre-pass blocks
    test::TempDir dir;
    ThreeEncodings files(header);
    for (std::size_t i = 0; i < kPoints; ++i) {
        const double x = i % 7919 == 11 ? std::numeric_limits<double>::infinity()
                                        : 577.123456789 + 0.0731 * static_cast<double>(i % 40000);
        const double y = 882.5 + 1e-7 * static_cast<double>(i * i % 1000003);
        const double z = 406.25 + std::sin(1e-4 * static_cast<double>(i));
        const glm::vec3 normal(0.0f, 0.6f, i % 2 == 0 ? 0.8f : -0.8f);
        files.vertex([&](PlyBytes& bytes) {
            bytes.put(x).put(y).put(z).put(normal.x).put(normal.y).put(normal.z);
            bytes.put(std::uint8_t(i % 251)).put(std::uint8_t(i % 13)).put(std::uint8_t(7));
            bytes.put(static_cast<std::uint16_t>(i % 60000));
        });
    }
    const ReadResult fast = files.readAll(dir);
    EXPECT_EQ(fast.summary.skippedNonFinite, 19u); // i = 11, 7930, ... below 150,000
    ASSERT_EQ(fast.points.size(), kPoints - 19);
    EXPECT_DOUBLE_EQ(fast.info.sourceBounds.min.x, 635577.123456789);
    expectNear(sourceOf(fast, 1), {635577.123456789 + 0.0731, 848882.5 + 1e-7, 406.25 + 1e-4},
               unitTolerance(fast));
}

// PDAL's PLY from a LAS file: double x y z, ushort intensity, LAS fields the reader ignores and
// ushort red green blue. The fast loops scale the colours to 8 bits exactly as the general
// code does (every 16-bit value, the ends included), little- and big-endian.
TEST(PlyReaderLayout, UShortColoursOnTheFastPathAgreeWithTheGeneralOne) {
    const std::string properties =
        "property double x\nproperty double y\nproperty double z\nproperty ushort intensity\n"
        "property uchar classification\nproperty ushort red\nproperty ushort green\n"
        "property ushort blue\n";
    constexpr std::size_t kPoints = 70'000; // more than every 16-bit value, two pre-pass blocks
    test::TempDir dir;
    ThreeEncodings files([&](const char* format, const std::string& more) {
        return binaryHeader(kPoints, properties + more, format);
    });
    for (std::size_t i = 0; i < kPoints; ++i) {
        const double x = 1000.0 + 0.25 * static_cast<double>(i % 1000);
        const double y = 2000.0 + 0.125 * static_cast<double>(i / 1000);
        const double z = i % 9001 == 17 ? std::numeric_limits<double>::quiet_NaN() : 3.5;
        const auto red = static_cast<std::uint16_t>(i % 65536);
        const auto green = static_cast<std::uint16_t>(65535 - i % 65536);
        const auto blue = static_cast<std::uint16_t>((i * 7919) % 65536);
        files.vertex([&](PlyBytes& bytes) {
            bytes.put(x).put(y).put(z).put(static_cast<std::uint16_t>(i)).put(std::uint8_t(2));
            bytes.put(red).put(green).put(blue);
        });
    }
    const ReadResult fast = files.readAll(dir);
    ASSERT_TRUE(fast.info.attributes.has(Attribute::Color));
    EXPECT_EQ(fast.summary.skippedNonFinite, 8u); // i = 17, 9018, ... below 70,000
    EXPECT_EQ(fast.points.colors[0], glm::u8vec3(0, 255, 0));
    // Points 128 and 129 (point 17 was skipped): 128 / 257 = 0.498 and 129 / 257 = 0.502 for
    // red, 65407 / 257 = 254.502 and 65406 / 257 = 254.498 for green.
    EXPECT_EQ(fast.points.colors[127], glm::u8vec3(0, 255, 119));
    EXPECT_EQ(fast.points.colors[128], glm::u8vec3(1, 254, 150));
}

// "property TYPE x" ... z, for tests run with float and with double positions.
std::string positionProperties(const std::string& type) {
    return "property " + type + " x\nproperty " + type + " y\nproperty " + type + " z\n";
}

// x y z stored as `type` (float or double).
void putPosition(PlyBytes& bytes, const std::string& type, double x, double y, double z) {
    if (type == "double") {
        bytes.put(x).put(y).put(z);
    } else {
        bytes.put(static_cast<float>(x)).put(static_cast<float>(y)).put(static_cast<float>(z));
    }
}

// Open3D's point cloud PLY: double x y z, double nx ny nz and uchar colours. The fast loops
// (float positions too, for the float loops with double normals) round each double normal to
// float as the general code does, little- and big-endian, bit for bit.
TEST(PlyReaderLayout, DoubleNormalsOnTheFastPathAgreeWithTheGeneralOne) {
    for (const char* position : {"double", "float"}) {
        SCOPED_TRACE(position);
        const std::string properties =
            positionProperties(position) +
            "property double nx\nproperty double ny\nproperty double nz\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n";
        constexpr std::size_t kPoints = 40'000;
        test::TempDir dir;
        ThreeEncodings files([&](const char* format, const std::string& more) {
            return binaryHeader(kPoints, properties + more, format);
        });
        for (std::size_t i = 0; i < kPoints; ++i) {
            const double x = 10.0 + 0.01 * static_cast<double>(i % 200);
            const double y = -5.0 + 0.02 * static_cast<double>(i / 200);
            const double z = i % 4999 == 3 ? std::numeric_limits<double>::quiet_NaN()
                                           : std::cos(1e-3 * static_cast<double>(i));
            // Doubles that floats cannot hold (a third, a tenth, a value one part in 2^40
            // off), some past the float range's small end, and unnormalised ones.
            const double angle = 1e-3 * static_cast<double>(i);
            const glm::dvec3 normal(std::sin(angle) / 3.0, 0.1 + std::ldexp(1.0, -40),
                                    i % 3 == 0 ? 1e-300 : std::cos(angle) * 7.0);
            files.vertex([&](PlyBytes& bytes) {
                putPosition(bytes, position, x, y, z);
                bytes.put(normal.x).put(normal.y).put(normal.z);
                bytes.put(std::uint8_t(i % 256)).put(std::uint8_t(3)).put(std::uint8_t(200));
            });
        }
        const ReadResult fast = files.readAll(dir);
        ASSERT_TRUE(fast.info.attributes.has(Attribute::Normal));
        EXPECT_EQ(fast.summary.skippedNonFinite, 9u); // i = 3, 5002, ..., 39995
        ASSERT_EQ(fast.points.size(), kPoints - 9);
        EXPECT_EQ(fast.points.normals[0],
                  glm::vec3(0.0f, static_cast<float>(0.1 + std::ldexp(1.0, -40)), 0.0f));
        EXPECT_EQ(fast.points.normals[1].x, static_cast<float>(std::sin(1e-3) / 3.0));
        EXPECT_EQ(fast.points.colors[1], glm::u8vec3(1, 3, 200));
    }
}

// Float colours from 0 to 1 (beside float positions, and double ones): the fast loops scale
// them to 8 bits as the general code does, values outside [0, 1], NaN and the roundings at
// half a step included, little- and big-endian.
TEST(PlyReaderLayout, FloatColoursOnTheFastPathAgreeWithTheGeneralOne) {
    for (const char* position : {"float", "double"}) {
        SCOPED_TRACE(position);
        const std::string properties =
            positionProperties(position) +
            "property float red\nproperty float green\nproperty float blue\n";
        constexpr std::size_t kPoints = 20'000;
        test::TempDir dir;
        ThreeEncodings files([&](const char* format, const std::string& more) {
            return binaryHeader(kPoints, properties + more, format);
        });
        const auto channel = [](std::size_t i) {
            switch (i % 5) {
            case 0:
                return static_cast<float>(i % 256) / 255.0f;
            case 1:
                return (static_cast<float>(i % 256) + 0.5f) / 255.0f; // half a step
            case 2:
                return i % 2 == 0 ? -0.25f : 1.75f;
            case 3:
                return std::numeric_limits<float>::quiet_NaN();
            default:
                return std::nextafter(1.0f, 0.0f);
            }
        };
        for (std::size_t i = 0; i < kPoints; ++i) {
            const double x = 3.0 + 0.5 * static_cast<double>(i % 100);
            const double y = 4.0 + 0.5 * static_cast<double>(i / 100);
            const double z = 1.0;
            files.vertex([&](PlyBytes& bytes) {
                putPosition(bytes, position, x, y, z);
                bytes.put(channel(i)).put(channel(i + 1)).put(channel(i + 2));
            });
        }
        const ReadResult fast = files.readAll(dir);
        ASSERT_TRUE(fast.info.attributes.has(Attribute::Color));
        ASSERT_EQ(fast.points.size(), kPoints);
        // Point 0: 0, 1.5 / 255 (half a step: rounds up to 2), -0.25 (clamped to 0); point 3:
        // NaN (0), 1 - ulp (255), 5 / 255.
        EXPECT_EQ(fast.points.colors[0], glm::u8vec3(0, 2, 0));
        EXPECT_EQ(fast.points.colors[3], glm::u8vec3(0, 255, 5));
    }
}

TEST(PlyReaderLayout, CrlfHeaderAndBody) {
    test::TempDir dir;
    const std::string binaryPath = dir.file("crlf.ply");
    PlyBytes bytes("ply\r\nformat binary_little_endian 1.0\r\ncomment offset 10 0 0\r\n"
                   "element vertex 1\r\nproperty float x\r\nproperty float y\r\n"
                   "property float z\r\nend_header\r\n");
    bytes.put(1.0f).put(2.0f).put(3.0f);
    bytes.write(binaryPath);
    const ReadResult binary = readAll(binaryPath);
    EXPECT_EQ(binary.info.sourceOffset, glm::dvec3(10, 0, 0));
    expectNear(sourceOf(binary, 0), {11, 2, 3}, 1e-9);

    const std::string asciiPath = dir.file("crlf_ascii.ply");
    test::writeText(asciiPath, "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\n"
                               "property float x\r\nproperty float y\r\nproperty float z\r\n"
                               "end_header\r\n1 2 3\r\n4 5 6\r\n");
    EXPECT_EQ(readAll(asciiPath).points.size(), 2u);
}

TEST(PlyReaderLayout, NonFinitePointsAreSkippedAndCounted) {
    test::TempDir dir;
    const std::string path = dir.file("nan.ply");
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    PlyBytes bytes(binaryHeader(5, "property float x\nproperty float y\nproperty float z\n"
                                   "property uchar red\nproperty uchar green\n"
                                   "property uchar blue\n"));
    const float points[5][3] = {{nan, 0, 0}, {1, 2, 3}, {0, -inf, 0}, {5, 6, 7}, {0, 0, inf}};
    for (const auto& p : points) {
        bytes.put(p[0])
            .put(p[1])
            .put(p[2])
            .put(std::uint8_t{1})
            .put(std::uint8_t{2})
            .put(std::uint8_t{3});
    }
    bytes.write(path);
    const ReadResult result = readAll(path);
    EXPECT_EQ(result.info.pointCount, 5u);
    EXPECT_EQ(result.summary.pointsDelivered, 2u);
    EXPECT_EQ(result.summary.skippedNonFinite, 3u);
    EXPECT_EQ(result.info.sourceBounds.min, glm::dvec3(1, 2, 3));
    EXPECT_EQ(result.info.sourceBounds.max, glm::dvec3(5, 6, 7));
    expectNear(sourceOf(result, 1), {5, 6, 7}, 1e-6);

    const std::string asciiPath = dir.file("nan_ascii.ply");
    test::writeText(asciiPath, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n"
                               "nan 1 1\n1 2 3\n4 inf 4\n");
    const ReadResult ascii = readAll(asciiPath);
    EXPECT_EQ(ascii.summary.pointsDelivered, 1u);
    EXPECT_EQ(ascii.summary.skippedNonFinite, 2u);
}

TEST(PlyReaderLayout, SinglePointGetsAUnitEdge) {
    test::TempDir dir;
    const std::string path = dir.file("one.ply");
    PlyBytes(binaryHeader(1)).put(5.0f).put(6.0f).put(7.0f).write(path);
    const ReadResult result = readAll(path);
    EXPECT_EQ(result.info.cube.edge, 1.0);
    EXPECT_EQ(result.points.positions[0], glm::vec3(0.0f));
}

// ---- the streaming contract --------------------------------------------------------------

std::string writeGrid(const test::TempDir& dir, std::size_t count, const std::string& format) {
    const std::string path = dir.file("grid_" + format + ".ply");
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Color);
    for (std::size_t i = 0; i < count; ++i) {
        batch.positions.emplace_back(float(i % 10) / 10.0f, float(i / 10 % 10) / 10.0f,
                                     float(i / 100) / float(count / 100 + 1));
        batch.colors.emplace_back(i % 256, 0, 0);
    }
    PlyWriteOptions options;
    options.encoding = format == "ascii" ? PlyEncoding::Ascii : PlyEncoding::BinaryLittleEndian;
    writePly(path, batch, CubeTransform{{0, 0, 0}, 10.0}, options);
    return path;
}

TEST(PlyReaderStreaming, BatchesHoldAtMostBatchPoints) {
    test::TempDir dir;
    for (const char* format : {"binary", "ascii"}) {
        const std::string path = writeGrid(dir, 2500, format);
        ReadOptions options;
        options.batchPoints = 1000;
        const ReadResult result = readAll(path, {}, options);
        EXPECT_EQ(result.summary.batches, 3u) << format;
        EXPECT_EQ(result.batchSizes, (std::vector<std::size_t>{1000, 1000, 500})) << format;
        EXPECT_EQ(result.summary.pointsDelivered, 2500u);
    }
}

TEST(PlyReaderStreaming, CancellationStopsBetweenBatches) {
    test::TempDir dir;
    for (const char* format : {"binary", "ascii"}) {
        const std::string path = writeGrid(dir, 5000, format);
        auto reader = openPlyReader(path, {});
        std::atomic<bool> cancel{false};
        ReadOptions options;
        options.batchPoints = 1000;
        options.cancel = &cancel;
        std::size_t delivered = 0;
        const ReadSummary summary = reader->read(
            [&](const PointBatch& batch) {
                delivered += batch.size();
                cancel = true;
            },
            options);
        EXPECT_TRUE(summary.cancelled) << format;
        EXPECT_EQ(summary.batches, 1u);
        EXPECT_EQ(summary.pointsDelivered, 1000u);
        EXPECT_EQ(delivered, 1000u);
    }
}

TEST(PlyReaderStreaming, CancelledBeforeReadDeliversNothing) {
    test::TempDir dir;
    auto reader = openPlyReader(writeGrid(dir, 100, "binary"), {});
    std::atomic<bool> cancel{true};
    ReadOptions options;
    options.cancel = &cancel;
    const ReadSummary summary = reader->read([](const PointBatch&) { FAIL(); }, options);
    EXPECT_TRUE(summary.cancelled);
    EXPECT_EQ(summary.batches, 0u);
}

TEST(PlyReaderStreaming, KnownBoundsSkipThePrePass) {
    // A bad value on the last line: the pre-pass would report it at open; with known bounds
    // open succeeds and read() finds it.
    test::TempDir dir;
    const std::string path = dir.file("late_error.ply");
    test::writeText(path, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n"
                          "0 0 0\n1 1 1\n2 2 oops\n");
    expectOpenError(path, InputErrorKind::MalformedValue, "line 10: ");
    OpenOptions options;
    options.knownBounds = Bounds{{-1, -1, -1}, {3, 3, 3}};
    auto reader = openPlyReader(path, options);
    EXPECT_EQ(reader->info().sourceBounds, *options.knownBounds);
    EXPECT_EQ(reader->info().cube, CubeTransform::fromBounds(*options.knownBounds));
    expectInputError([&] { reader->read([](const PointBatch&) {}); },
                     InputErrorKind::MalformedValue, path, "line 10: ");
}

TEST(PlyReaderStreaming, PointOutsideKnownBoundsThrowsOutOfBounds) {
    test::TempDir dir;
    const std::string path = dir.file("outside.ply");
    PlyBytes bytes(binaryHeader(3));
    bytes.put(0.0f).put(0.0f).put(0.0f).put(1.0f).put(1.0f).put(1.0f).put(1.0f).put(5.0f).put(1.0f);
    bytes.write(path);
    OpenOptions options;
    options.knownBounds = Bounds{{0, 0, 0}, {1, 1, 1}};
    const std::size_t third = binaryHeader(3).size() + 2 * 12;
    const std::string message = expectReadError(path, InputErrorKind::OutOfBounds,
                                                "byte " + std::to_string(third) + ": ", options);
    EXPECT_NE(message.find("5.0"), std::string::npos) << message;

    const std::string asciiPath = dir.file("outside.txt.ply");
    test::writeText(asciiPath, "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n"
                               "0 0 0\n0 -2 0\n");
    expectReadError(asciiPath, InputErrorKind::OutOfBounds, "line 9: ", options);
}

// ---- ascii bodies of many blocks (parsed in parallel, visited in file order) ---------------

// An ascii PLY of `vertices` vertices "i i%1000 0.5" (blank lines sprinkled in), followed by
// `faces` face lines of four corners when faces > 0.
std::string asciiPly(int vertices, int faces) {
    std::string text = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
                       "\nproperty float x\nproperty float y\nproperty float z\n";
    if (faces > 0) {
        text += "element face " + std::to_string(faces) + "\nproperty list uchar int idx\n";
    }
    text += "end_header\n";
    for (int i = 0; i < vertices; ++i) {
        text += std::to_string(i) + " " + std::to_string(i % 1000) + " 0.5\n";
        if (i % 5000 == 0) {
            text += "\n";
        }
    }
    for (int f = 0; f < faces; ++f) {
        text += "4 0 1 2 3\n";
    }
    return text;
}

// The line of vertex `i` in asciiPly: 7 header lines (9 with faces) and the blank lines.
std::uint64_t lineOfVertex(int i, bool faces) {
    return (faces ? 10 : 8) + static_cast<std::uint64_t>(i + (i + 4999) / 5000);
}

TEST(PlyReaderAsciiBlocks, EveryVertexInFileOrderAndTheFacesAfterThemAreNotRead) {
    test::TempDir dir;
    const std::string path = dir.file("mesh.ply");
    constexpr int kVertices = 200'000; // about 3 MB: several groups of blocks
    test::writeText(path, asciiPly(kVertices, 100'000));
    const ReadResult result = readAll(path);
    ASSERT_EQ(result.points.size(), static_cast<std::size_t>(kVertices));
    EXPECT_EQ(result.info.sourceBounds.max, glm::dvec3(kVertices - 1, 999, 0.5));
    for (int i = 0; i < kVertices; i += 991) {
        const glm::dvec3 source = result.info.cube.toSource(result.points.positions[i]);
        EXPECT_NEAR(source.x, i, 0.05);
        EXPECT_NEAR(source.y, i % 1000, 0.05);
    }
}

// Opening `text` saved as a PLY fails with `kind` at line `line`, saying `mention`.
void expectAsciiOpenError(const std::string& text, InputErrorKind kind, std::uint64_t line,
                          const std::string& mention) {
    test::TempDir dir;
    const std::string path = dir.file("body.ply");
    test::writeText(path, text);
    const std::string message = expectInputError([&] { openPlyReader(path, {}); }, kind, path,
                                                 "line " + std::to_string(line) + ": ");
    EXPECT_NE(message.find(mention), std::string::npos) << message;
}

TEST(PlyReaderAsciiBlocks, TheFirstBadVertexOfTheFileIsNamed) {
    std::string text = asciiPly(200'000, 0);
    const auto replaceLine = [&](std::uint64_t number, const std::string& with) {
        std::size_t at = 0;
        for (std::uint64_t line = 1; line < number; ++line) {
            at = text.find('\n', at) + 1;
        }
        text.replace(at, text.find('\n', at) - at, with);
    };
    // Two bad vertices in one group of blocks (on two cores or more): the later may fail first.
    replaceLine(lineOfVertex(150'000, false), "1 2 oops");
    replaceLine(lineOfVertex(60'000, false), "1 2");
    expectAsciiOpenError(text, InputErrorKind::MalformedValue, lineOfVertex(60'000, false),
                         "vertex 60000: found only 2 values");
}

TEST(PlyReaderAsciiBlocks, DataAfterTheLastVertexBlocksLaterIsAnError) {
    // The header says 100,000 vertices, the body holds 200,000: the first extra one is named.
    std::string text = asciiPly(200'000, 0);
    text.replace(text.find("element vertex 200000"), 21, "element vertex 100000");
    expectAsciiOpenError(text, InputErrorKind::CountMismatch, lineOfVertex(100'000, false),
                         "vertex count");
}

TEST(PlyReaderAsciiBlocks, FewerVerticesThanDeclaredNameTheLineAfterTheLast) {
    std::string text = asciiPly(200'000, 0);
    text.replace(text.find("element vertex 200000"), 21, "element vertex 300000");
    const auto lines = static_cast<std::uint64_t>(std::count(text.begin(), text.end(), '\n'));
    expectAsciiOpenError(text, InputErrorKind::Truncated, lines + 1, "vertex 200000 of 300000");
}

// ---- malformed input ---------------------------------------------------------------------

struct MalformedHeader {
    const char* name;
    const char* text;
    InputErrorKind kind;
    const char* where;    // the location the message must give
    const char* mentions; // something the detail must name
};

const MalformedHeader kMalformedHeaders[] = {
    {"MissingMagic", "plx\nformat ascii 1.0\n", InputErrorKind::UnknownFormat, "line 1: ", "'ply'"},
    {"MissingFormatLine", "ply\nelement vertex 1\nproperty float x\nend_header\n",
     InputErrorKind::MalformedHeader, "line 2: ", "format"},
    {"BadFormatLine", "ply\nformat binary_little_endian\nend_header\n",
     InputErrorKind::MalformedHeader, "line 2: ", "format"},
    {"UnknownFormat", "ply\nformat binary_middle_endian 1.0\nend_header\n",
     InputErrorKind::UnsupportedFeature, "line 2: ", "binary_middle_endian"},
    {"UnsupportedVersion", "ply\nformat ascii 2.0\nend_header\n",
     InputErrorKind::UnsupportedFeature, "line 2: ", "2.0"},
    {"BadElementLine", "ply\nformat ascii 1.0\nelement vertex\nend_header\n",
     InputErrorKind::MalformedHeader, "line 3: ", "element NAME COUNT"},
    {"NonNumericCount", "ply\nformat ascii 1.0\nelement vertex many\nend_header\n",
     InputErrorKind::MalformedHeader, "line 3: ", "whole-number"},
    {"NegativeCount", "ply\nformat ascii 1.0\nelement vertex -5\nend_header\n",
     InputErrorKind::MalformedHeader, "line 3: ", "negative"},
    {"CountTooLarge", "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\n",
     InputErrorKind::MalformedHeader, "line 3: ", "too large"},
    {"CountTimesSizeOverflows",
     "ply\nformat binary_little_endian 1.0\nelement vertex 4611686018427387904\n"
     "property float x\nproperty float y\nproperty float z\nend_header\n",
     InputErrorKind::MalformedHeader, "line 7: ", "overflows"},
    {"BadPropertyLine", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float\nend_header\n",
     InputErrorKind::MalformedHeader, "line 4: ", "property TYPE NAME"},
    {"UnknownType", "ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n",
     InputErrorKind::UnsupportedFeature, "line 4: ", "'half'"},
    {"FloatListCount",
     "ply\nformat ascii 1.0\nelement face 1\nproperty list float int idx\nend_header\n",
     InputErrorKind::MalformedHeader, "line 4: ", "integer"},
    {"PropertyBeforeElement", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
     InputErrorKind::MalformedHeader, "line 3: ", "before any 'element'"},
    {"DuplicateProperty",
     "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\nend_header\n",
     InputErrorKind::MalformedHeader, "line 5: ", "second property 'x'"},
    {"UnknownKeyword", "ply\nformat ascii 1.0\nelement vertex 1\nvertex float x\nend_header\n",
     InputErrorKind::MalformedHeader, "line 4: ", "end_header"},
    {"BadOffsetComment", "ply\nformat ascii 1.0\ncomment offset 1 two 3\nend_header\n",
     InputErrorKind::MalformedHeader, "line 3: ", "comment offset X Y Z"},
    {"NoVertexElement",
     "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int idx\nend_header\n",
     InputErrorKind::MalformedHeader, "line 5: ", "'face'"},
    {"MissingY",
     "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\nend_header\n"
     "1 2\n",
     InputErrorKind::MalformedHeader, "line 3: ", "no property 'y'"},
    {"ListCoordinate",
     "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\n"
     "property float z\nend_header\n",
     InputErrorKind::MalformedHeader, "line 3: ", "'x' is a list"},
    {"FileEndsInHeader", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
     InputErrorKind::Truncated, "line 5: ", "end_header"},
    {"ZeroVertices",
     "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n",
     InputErrorKind::NoPoints, "line 3: ", "0 vertices"},
    {"AsciiTooFewValues",
     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n1 2 3\n4 5\n",
     InputErrorKind::MalformedValue, "line 9: ", "only 2 values"},
    {"AsciiTooManyValues",
     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n1 2 3 4\n4 5 6\n",
     InputErrorKind::MalformedValue, "line 8: ", "more than"},
    {"AsciiNonNumeric",
     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n1 2 3\n4 five 6\n",
     InputErrorKind::MalformedValue, "line 9: ", "'five'"},
    {"AsciiNegativeListLength",
     "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
     "property float z\nproperty list uchar int ids\nend_header\n1 2 3 -1\n",
     InputErrorKind::MalformedValue, "line 9: ", "list length"},
    {"AsciiFewerLinesThanDeclared",
     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n1 2 3\n4 5 6\n",
     InputErrorKind::Truncated, "line 10: ", "vertex 2 of 3"},
    {"AsciiMoreLinesThanDeclared",
     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n1 2 3\n4 5 6\n7 8 9\n",
     InputErrorKind::CountMismatch, "line 10: ", "vertex count"},
    {"AsciiFacesMissing",
     "ply\nformat ascii 1.0\nelement face 3\nproperty list uchar int idx\nelement vertex 1\n"
     "property float x\nproperty float y\nproperty float z\nend_header\n3 0 0 0\n",
     InputErrorKind::Truncated, "line ", "'face'"},
    {"AsciiAbsurdCount",
     "ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\n"
     "property float z\nend_header\n1 2 3\n",
     InputErrorKind::Truncated, "line 8: ", "1000000000000 vertices"},
    {"AsciiAllNaN",
     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
     "property float z\nend_header\nnan 0 0\n0 nan 0\n",
     InputErrorKind::NoPoints, "line 8: ", "non-finite"},
};

class PlyMalformedInput : public testing::TestWithParam<MalformedHeader> {};

TEST_P(PlyMalformedInput, IsRejectedAtOpen) {
    const MalformedHeader& input = GetParam();
    test::TempDir dir;
    const std::string path = dir.file(std::string(input.name) + ".ply");
    test::writeText(path, input.text);
    const std::string message = expectOpenError(path, input.kind, input.where);
    EXPECT_NE(message.find(input.mentions), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(Ply, PlyMalformedInput, testing::ValuesIn(kMalformedHeaders),
                         [](const testing::TestParamInfo<MalformedHeader>& info) {
                             return std::string(info.param.name);
                         });

TEST(PlyReaderMalformed, HeaderWithoutEndIsTooLong) {
    test::TempDir dir;
    const std::string path = dir.file("long_header.ply");
    std::string text = "ply\nformat binary_little_endian 1.0\n";
    while (text.size() < (std::size_t{1} << 20) + 100) {
        text += "comment this header never ends ...............................................\n";
    }
    test::writeText(path, text);
    const std::string message = expectOpenError(path, InputErrorKind::MalformedHeader, "line ");
    EXPECT_NE(message.find("end_header"), std::string::npos) << message;
}

TEST(PlyReaderMalformed, TruncatedBinaryBodyNamesTheVertex) {
    test::TempDir dir;
    const std::string path = dir.file("truncated.ply");
    PlyBytes bytes(binaryHeader(3));
    bytes.put(0.0f).put(0.0f).put(0.0f).put(1.0f).put(1.0f).put(1.0f).put(2.0f).put(2.0f);
    bytes.write(path);
    const std::size_t third = binaryHeader(3).size() + 24;
    const std::string message =
        expectOpenError(path, InputErrorKind::Truncated, "byte " + std::to_string(third) + ": ");
    EXPECT_NE(message.find("vertex 2 of 3"), std::string::npos) << message;
    EXPECT_NE(message.find("ends at byte " + std::to_string(bytes.size())), std::string::npos)
        << message;

    // Known bounds skip the pre-pass, but not the size check.
    OpenOptions options;
    options.knownBounds = Bounds{{0, 0, 0}, {2, 2, 2}};
    expectInputError([&] { openPlyReader(path, options); }, InputErrorKind::Truncated, path,
                     "byte " + std::to_string(third) + ": ");
}

TEST(PlyReaderMalformed, TrailingBytesAfterTheLastVertex) {
    test::TempDir dir;
    const std::string path = dir.file("trailing.ply");
    PlyBytes bytes(binaryHeader(1));
    bytes.put(0.0f).put(0.0f).put(0.0f).put(std::uint16_t{7});
    bytes.write(path);
    const std::size_t end = binaryHeader(1).size() + 12;
    const std::string message =
        expectOpenError(path, InputErrorKind::CountMismatch, "byte " + std::to_string(end) + ": ");
    EXPECT_NE(message.find("2 more bytes"), std::string::npos) << message;
}

TEST(PlyReaderMalformed, TrailingBytesAfterLaterElementsAreNotChecked) {
    test::TempDir dir;
    const std::string path = dir.file("trailing_faces.ply");
    PlyBytes bytes("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 0\n"
                   "property list uchar int idx\nend_header\n");
    bytes.put(0.0f).put(0.0f).put(0.0f).put(std::uint16_t{7});
    bytes.write(path);
    EXPECT_EQ(readAll(path).points.size(), 1u);
}

TEST(PlyReaderMalformed, TruncatedFacesBeforeVertices) {
    test::TempDir dir;
    const std::string path = dir.file("truncated_faces.ply");
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement face 2\n"
                               "property list uchar int idx\nelement vertex 1\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "end_header\n";
    PlyBytes bytes(header);
    bytes.put(std::uint8_t{3}).put(0).put(1).put(2).put(std::uint8_t{200}).put(0);
    bytes.write(path);
    const std::string message = expectOpenError(
        path, InputErrorKind::Truncated, "byte " + std::to_string(header.size() + 13) + ": ");
    EXPECT_NE(message.find("face 1"), std::string::npos) << message;
}

TEST(PlyReaderMalformed, TruncatedListInsideVertices) {
    test::TempDir dir;
    const std::string path = dir.file("truncated_lists.ply");
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "property list uchar int ids\nend_header\n";
    PlyBytes bytes(header);
    bytes.put(0.0f).put(0.0f).put(0.0f).put(std::uint8_t{1}).put(5);
    bytes.put(1.0f).put(1.0f).put(1.0f).put(std::uint8_t{2}).put(5);
    bytes.write(path);
    const std::string message = expectOpenError(
        path, InputErrorKind::Truncated, "byte " + std::to_string(header.size() + 17) + ": ");
    EXPECT_NE(message.find("vertex 1 (of 2)"), std::string::npos) << message;
}

TEST(PlyReaderMalformed, TrailingBytesAfterVariableSizeVertices) {
    test::TempDir dir;
    const std::string path = dir.file("trailing_lists.ply");
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 1\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "property list uchar int ids\nend_header\n";
    PlyBytes bytes(header);
    bytes.put(0.0f).put(0.0f).put(0.0f).put(std::uint8_t{0}).put(std::uint8_t{0});
    bytes.write(path);
    expectOpenError(path, InputErrorKind::CountMismatch,
                    "byte " + std::to_string(header.size() + 13) + ": ");
}

TEST(PlyReaderMalformed, NegativeBinaryListLength) {
    test::TempDir dir;
    const std::string path = dir.file("negative_list.ply");
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 1\n"
                               "property list char int ids\nproperty float x\nproperty float y\n"
                               "property float z\nend_header\n";
    PlyBytes bytes(header);
    bytes.put(std::int8_t{-2}).put(0.0f).put(0.0f).put(0.0f);
    bytes.write(path);
    expectOpenError(path, InputErrorKind::MalformedValue,
                    "byte " + std::to_string(header.size()) + ": ");
}

TEST(PlyReaderMalformed, AllPointsNonFinite) {
    test::TempDir dir;
    const std::string path = dir.file("all_nan.ply");
    const float nan = std::numeric_limits<float>::quiet_NaN();
    PlyBytes bytes(binaryHeader(2));
    bytes.put(nan).put(0.0f).put(0.0f).put(0.0f).put(nan).put(0.0f);
    bytes.write(path);
    const std::string body = "byte " + std::to_string(binaryHeader(2).size()) + ": ";
    expectOpenError(path, InputErrorKind::NoPoints, body);
    OpenOptions options;
    options.knownBounds = Bounds{{0, 0, 0}, {1, 1, 1}};
    expectReadError(path, InputErrorKind::NoPoints, body, options);
}

TEST(PlyReaderMalformed, MissingFileAndDirectory) {
    test::TempDir dir;
    expectInputError([&] { openPlyReader(dir.file("absent.ply"), {}); }, InputErrorKind::CannotOpen,
                     dir.file("absent.ply"), "cannot open");
    expectInputError([&] { openPlyReader(dir.path().string(), {}); },
                     InputErrorKind::NotARegularFile, dir.path().string(), "directory");
}

} // namespace

// fuzz_ply found pointer arithmetic on the absent normals' null pointer (UBSan: "applying
// non-zero offset to null pointer") in a binary PLY of float positions without normals; the
// file must read (or fail with an InputError) cleanly. Meaningful under the asan preset's UBSan.
TEST(PlyReaderFuzzRegression, PositionsWithoutNormalsOrColours) {
    static const unsigned char bytes[] = {
    0x70, 0x6c, 0x79, 0x0a, 0x66, 0x6f, 0x72, 0x6d, 0x61, 0x74, 0x20, 0x62, 0x69, 0x6e, 0x61,
    0x72, 0x79, 0x5f, 0x6c, 0x69, 0x74, 0x74, 0x6c, 0x65, 0x5f, 0x65, 0x6e, 0x64, 0x69, 0x61,
    0x6e, 0x20, 0x31, 0x2e, 0x30, 0x0a, 0x63, 0x6f, 0x6d, 0x6d, 0x65, 0x6e, 0x74, 0x20, 0x73,
    0x6f, 0x75, 0x6f, 0x6e, 0x29, 0x0a, 0x65, 0x6c, 0x65, 0x6d, 0x65, 0x6e, 0x74, 0x20, 0x76,
    0x65, 0x72, 0x74, 0x65, 0x78, 0x20, 0x33, 0x0a, 0x70, 0x72, 0x6f, 0x70, 0x65, 0x72, 0x74,
    0x79, 0x20, 0x66, 0x6c, 0x6f, 0x61, 0x74, 0x20, 0x78, 0x0a, 0x70, 0x72, 0x6f, 0x70, 0x65,
    0x72, 0x74, 0x79, 0x20, 0x66, 0x6c, 0x6f, 0x61, 0x74, 0x20, 0x79, 0x0a, 0x70, 0x72, 0x6f,
    0x70, 0x65, 0x72, 0x74, 0x79, 0x20, 0x66, 0x6c, 0x6f, 0x61, 0x74, 0x20, 0x7a, 0x0a, 0x70,
    0x72, 0x6f, 0x70, 0x65, 0x72, 0x74, 0x79, 0x20, 0x75, 0x63, 0x68, 0x61, 0x72, 0x20, 0x62,
    0x6c, 0x65, 0x0a, 0x65, 0x6e, 0x64, 0x5f, 0x68, 0x65, 0x61, 0x64, 0x65, 0x72, 0x0a, 0x4c,
    0x5f, 0x65, 0x6e, 0x64, 0x69, 0x61, 0x6e, 0x0a, 0x63, 0x6c, 0x74, 0x20, 0x6e, 0x78, 0x0a,
    0x20, 0x0a, 0x79, 0x72, 0x70, 0x70, 0x6e, 0x6f, 0x66, 0x6c, 0x6f, 0x61, 0x74, 0x20, 0x6e,
    0x7a, 0xa0, 0x92, 0x3b, 0x95, 0x3a, 0x47, 0x3e
    };
    test::TempDir dir;
    const std::string path = dir.file("fuzz-regression.ply");
    {
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes), sizeof(bytes));
    }
    try {
        const LoadedCloud cloud = loadPointCloud(path);
        EXPECT_LE(cloud.points.size(), 3u);
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    }
}

} // namespace omicron
