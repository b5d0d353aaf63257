// Hot loops for the common binary PLY layout: native-endian float (or double) x y z, optionally
// float or double normals, uchar, ushort or float colours and a ushort or float intensity, no
// lists. Both loops do only loads, a few compares and the SourceNormalizer arithmetic, with an
// SSE2 path when x y z are adjacent floats; everything unusual (non-finite points, points at or
// outside the bounds) is left to the caller's exact code.
#pragma once

#include "io/source_normalizer.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/gtc/type_precision.hpp>
#include <limits>

namespace omicron {

// Readable bytes every record buffer must have past its last record: the SIMD loads read a
// 16-byte vector starting at x.
constexpr std::size_t kFloatRecordPadding = 16;

struct FloatRecordLayout {
    std::size_t recordBytes = 0;
    std::array<std::size_t, 3> position{}; // byte offsets of x y z (float, or double below)
    bool doublePositions = false;          // the double loops: extendDoubleBounds, convertDouble…
    // float, or double (Open3D writes double normals; read as the general code does, rounded
    // to float)
    enum class Normals { None, Float, Double } normalType = Normals::None;
    std::array<std::size_t, 3> normal{};
    // uchar (copied), ushort (scaled to 8 bits as plyColorChannel: PDAL writes LAS colours so)
    // or float (0 to 1, scaled to 8 bits as plyColorChannel)
    enum class Color { None, UChar, UShort, Float } colorType = Color::None;
    std::array<std::size_t, 3> color{};
    // ushort (copied), or float (rounded and clamped as plyIntensity: CloudCompare's
    // scalar_Intensity)
    enum class Intensity { None, UShort, Float } intensityType = Intensity::None;
    std::size_t intensity = 0;

    bool adjacentPosition() const { // float x y z side by side: the SSE2 loops
        return !doublePositions && position[1] == position[0] + 4 && position[2] == position[0] + 8;
    }
};

// Min/max of the finite stored positions seen so far.
struct FloatBox {
    std::array<float, 3> low{std::numeric_limits<float>::infinity(),
                             std::numeric_limits<float>::infinity(),
                             std::numeric_limits<float>::infinity()};
    std::array<float, 3> high{-std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity()};
    std::uint64_t finite = 0;
};

// Extends `box` by the finite positions of `count` records; records with a NaN or infinite
// coordinate are left out (the caller counts them as count - finite).
void extendFloatBox(const std::uint8_t* records, std::size_t count, const FloatRecordLayout& layout,
                    FloatBox& box);

// What the conversion loop needs: SourceNormalizer's arithmetic, and a box of stored floats
// inside which every point certainly passes SourceNormalizer::inBounds.
struct FloatUnitTransform {
    glm::dvec3 offset{0.0};
    glm::dvec3 origin{0.0};
    double inverseEdge = 1.0;
    std::array<float, 3> low{};
    std::array<float, 3> high{};

    // `offset`: added to stored floats to get source coordinates. `bounds`: those the
    // normalizer was built with.
    FloatUnitTransform(const SourceNormalizer& normalizer, const CubeTransform& cube,
                       const Bounds& bounds, const glm::dvec3& offset);
};

struct FloatRecordOutputs {
    glm::vec3* positions = nullptr;
    glm::vec3* normals = nullptr;  // when the layout has normals
    glm::u8vec3* colors = nullptr; // when the layout has colours
    std::uint16_t* intensities = nullptr; // when the layout has an intensity
};

// A record's source position: its stored x y z (float or double) as doubles, plus `offset`.
glm::dvec3 sourcePosition(const std::uint8_t* record, const FloatRecordLayout& layout,
                          const glm::dvec3& offset);

// The bounds of the finite source positions (stored double + offset) of `count` records with
// double x y z, and how many there are.
struct DoubleBounds {
    Bounds box;
    std::uint64_t finite = 0;
};
void extendDoubleBounds(const std::uint8_t* records, std::size_t count,
                        const FloatRecordLayout& layout, const glm::dvec3& offset,
                        DoubleBounds& bounds);

// convertFloatRecords for double x y z: each position is checked with the normalizer itself.
std::size_t convertDoubleRecords(const std::uint8_t* records, std::size_t count,
                                 const FloatRecordLayout& layout,
                                 const SourceNormalizer& normalizer, const glm::dvec3& offset,
                                 const FloatRecordOutputs& outputs);

// Converts records in order while each lies inside the transform's box, writing position i
// as float(((double(x) + offset) - origin) * inverseEdge), exactly SourceNormalizer::toUnit,
// plus its normal, colour and intensity. Returns how many were converted: `count`, or the index of
// the first record that needs the caller's exact handling.
std::size_t convertFloatRecords(const std::uint8_t* records, std::size_t count,
                                const FloatRecordLayout& layout,
                                const FloatUnitTransform& transform,
                                const FloatRecordOutputs& outputs);

} // namespace omicron
