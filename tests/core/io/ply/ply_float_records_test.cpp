// The fast PLY loops against the exact per-point rules they stand in for: the prefilter box
// must accept exactly the floats SourceNormalizer accepts, and conversion must match toUnit
// bit for bit, on the SSE2 path (adjacent x y z) and the scalar one alike.
#include "io/ply/ply_float_records.hpp"

#include <cmath>
#include <cstring>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <vector>

namespace omicron {
namespace {

struct Case {
    glm::dvec3 offset;
    Bounds bounds;
};

const Case kCases[] = {
    {{0, 0, 0}, {{-1.5, 0.25, 3.0}, {2.0, 0.75, 3.0}}}, // flat in z
    {{635000, 848000, 0}, {{635577.79, 848882.15, 406.14}, {638923.87, 850999.99, 615.26}}},
    {{0, 0, 0}, {{1e-7, -2e-7, 0.0}, {3e-7, 1e-7, 1e-9}}},                             // tiny
    {{589000, 231000, 0}, {{589500.0, 231300.0, 722.5}, {589500.0, 231300.0, 722.5}}}, // a point
};

TEST(PlyFloatRecords, PrefilterBoxIsExactlyTheNormalizersBounds) {
    for (const Case& c : kCases) {
        const CubeTransform cube = CubeTransform::fromBounds(c.bounds);
        const SourceNormalizer normalizer(cube, c.bounds, 0.0);
        const FloatUnitTransform transform(normalizer, cube, c.bounds, c.offset);
        const glm::dvec3 center = (c.bounds.min + c.bounds.max) * 0.5;
        for (int axis = 0; axis < 3; ++axis) {
            const auto passes = [&](float stored) {
                glm::dvec3 probe = center;
                probe[axis] = static_cast<double>(stored) + c.offset[axis];
                return normalizer.inBounds(probe);
            };
            const float low = transform.low[axis];
            const float high = transform.high[axis];
            ASSERT_LE(low, high) << "axis " << axis;
            const float infinity = std::numeric_limits<float>::infinity();
            EXPECT_TRUE(passes(low));
            EXPECT_TRUE(passes(high));
            EXPECT_FALSE(passes(std::nextafter(low, -infinity)));
            EXPECT_FALSE(passes(std::nextafter(high, infinity)));
        }
    }
}

// Records holding x y z (adjacent, or scattered among the colour bytes) and uchar colours.
std::vector<std::uint8_t> makeRecords(const std::vector<glm::vec3>& points, bool adjacent,
                                      FloatRecordLayout& layout) {
    layout.recordBytes = adjacent ? 15 : 18;
    layout.position =
        adjacent ? std::array<std::size_t, 3>{0, 4, 8} : std::array<std::size_t, 3>{14, 1, 7};
    layout.colorType = FloatRecordLayout::Color::UChar;
    layout.color =
        adjacent ? std::array<std::size_t, 3>{12, 13, 14} : std::array<std::size_t, 3>{0, 5, 6};
    std::vector<std::uint8_t> bytes(points.size() * layout.recordBytes + kFloatRecordPadding, 0xff);
    for (std::size_t i = 0; i < points.size(); ++i) {
        std::uint8_t* record = bytes.data() + i * layout.recordBytes;
        for (int axis = 0; axis < 3; ++axis) {
            std::memcpy(record + layout.position[axis], &points[i][axis], 4);
            record[layout.color[axis]] = static_cast<std::uint8_t>(i * 3 + axis);
        }
    }
    return bytes;
}

TEST(PlyFloatRecords, BoundsNoFloatCanReachGiveAnEmptyBox) {
    // 722.555 lies between two floats and the tolerance is far below a float step: no stored
    // value passes, so every point must take the exact path (which then rejects it).
    const Bounds bounds{{0.0, 0.0, 722.555}, {1.0, 1.0, 722.555}};
    const CubeTransform cube = CubeTransform::fromBounds(bounds);
    const SourceNormalizer normalizer(cube, bounds, 0.0);
    const FloatUnitTransform transform(normalizer, cube, bounds, glm::dvec3(0.0));
    EXPECT_GT(transform.low[2], transform.high[2]);
    EXPECT_LE(transform.low[0], transform.high[0]);
}

TEST(PlyFloatRecords, ConversionMatchesSourceNormalizerBitForBit) {
    std::mt19937 random(3);
    std::uniform_real_distribution<float> coordinate(-2000.0f, 4000.0f);
    std::vector<glm::vec3> points(1000);
    Bounds bounds;
    const glm::dvec3 offset(635000, 848000, 0);
    for (glm::vec3& p : points) {
        p = {coordinate(random), coordinate(random), coordinate(random) * 0.01f};
        bounds.extend(glm::dvec3(p) + offset);
    }
    const CubeTransform cube = CubeTransform::fromBounds(bounds);
    const SourceNormalizer normalizer(cube, bounds, 0.0);
    for (const bool adjacent : {true, false}) {
        FloatRecordLayout layout;
        const std::vector<std::uint8_t> records = makeRecords(points, adjacent, layout);

        FloatBox box;
        extendFloatBox(records.data(), points.size(), layout, box);
        EXPECT_EQ(box.finite, points.size());
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_EQ(static_cast<double>(box.low[axis]) + offset[axis], bounds.min[axis]);
            EXPECT_EQ(static_cast<double>(box.high[axis]) + offset[axis], bounds.max[axis]);
        }

        const FloatUnitTransform transform(normalizer, cube, bounds, offset);
        std::vector<glm::vec3> positions(points.size());
        std::vector<glm::u8vec3> colors(points.size());
        FloatRecordOutputs outputs;
        outputs.positions = positions.data();
        outputs.colors = colors.data();
        ASSERT_EQ(convertFloatRecords(records.data(), points.size(), layout, transform, outputs),
                  points.size());
        for (std::size_t i = 0; i < points.size(); ++i) {
            ASSERT_EQ(positions[i], normalizer.toUnit(glm::dvec3(points[i]) + offset)) << i;
            ASSERT_EQ(colors[i], glm::u8vec3(i * 3, i * 3 + 1, i * 3 + 2)) << i;
        }
    }
}

TEST(PlyFloatRecords, ConversionStopsAtPointsNeedingExactChecks) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<glm::vec3> points = {
        {0, 0, 0}, {1, 1, 1}, {nan, 0, 0}, {0.5f, 0.5f, 0.5f}, {0, 2, 0}};
    const Bounds bounds{{0, 0, 0}, {1, 1, 1}};
    const CubeTransform cube = CubeTransform::fromBounds(bounds);
    const SourceNormalizer normalizer(cube, bounds, 0.0);
    const FloatUnitTransform transform(normalizer, cube, bounds, glm::dvec3(0.0));
    for (const bool adjacent : {true, false}) {
        FloatRecordLayout layout;
        const std::vector<std::uint8_t> records = makeRecords(points, adjacent, layout);
        std::vector<glm::vec3> positions(points.size());
        std::vector<glm::u8vec3> colors(points.size());
        FloatRecordOutputs outputs{positions.data(), nullptr, colors.data()};
        EXPECT_EQ(convertFloatRecords(records.data(), 5, layout, transform, outputs), 2u);
        const std::uint8_t* fourth = records.data() + 3 * layout.recordBytes;
        EXPECT_EQ(convertFloatRecords(fourth, 2, layout, transform, outputs), 1u);

        FloatBox box;
        extendFloatBox(records.data(), points.size(), layout, box);
        EXPECT_EQ(box.finite, 4u);
        EXPECT_EQ(box.high[1], 2.0f);
    }
}

} // namespace
} // namespace omicron
