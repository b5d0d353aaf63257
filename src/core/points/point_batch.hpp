// The point model: a batch of points as structure of arrays.
//
// Positions are float in the cloud's unit cube (see CubeTransform for the way back to source
// units). Optional attributes are either absent (empty vector) or have one entry per point.
// Structure of arrays was chosen because the hot consumers (Morton coding, sorting, bounds)
// touch positions only; bench/morton_bench measures coding over SoA vs packed records.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/gtc/type_precision.hpp>
#include <glm/vec3.hpp>
#include <vector>

namespace omicron {

enum class Attribute : std::uint8_t {
    Normal = 1u << 0,
    Color = 1u << 1,     // 8-bit RGB; 16-bit sources are scaled to 8 bits
    Intensity = 1u << 2, // 16-bit
};

// A set of optional attributes.
class AttributeSet {
public:
    constexpr AttributeSet() = default;
    constexpr AttributeSet(Attribute a) : m_bits(static_cast<std::uint8_t>(a)) {}
    constexpr bool has(Attribute a) const { return (m_bits & static_cast<std::uint8_t>(a)) != 0; }
    constexpr AttributeSet& add(Attribute a) {
        m_bits |= static_cast<std::uint8_t>(a);
        return *this;
    }
    constexpr AttributeSet operator|(Attribute a) const { return AttributeSet(*this).add(a); }
    constexpr std::uint8_t bits() const { return m_bits; }
    friend constexpr bool operator==(AttributeSet, AttributeSet) = default;

private:
    std::uint8_t m_bits = 0;
};

// Bytes of one point with `attributes` as the point model keeps it: position, then normal,
// colour and intensity where present (a PointBatch, an exact SortedCloud).
constexpr std::size_t pointBytes(AttributeSet attributes) {
    return sizeof(glm::vec3) + (attributes.has(Attribute::Normal) ? sizeof(glm::vec3) : 0) +
           (attributes.has(Attribute::Color) ? sizeof(glm::u8vec3) : 0) +
           (attributes.has(Attribute::Intensity) ? sizeof(std::uint16_t) : 0);
}

struct PointBatch {
    AttributeSet attributes; // which optional vectors below are filled (one entry per point)
    std::vector<glm::vec3> positions; // unit cube
    std::vector<glm::vec3> normals;   // unit length where the source had them; may be (0,0,0)
    std::vector<glm::u8vec3> colors;
    std::vector<std::uint16_t> intensities;

    std::size_t size() const { return positions.size(); }
    bool empty() const { return positions.empty(); }

    // True when every present attribute has exactly one entry per point.
    bool consistent() const {
        const auto matches = [&](Attribute a, std::size_t n) {
            return attributes.has(a) ? n == size() : n == 0;
        };
        return matches(Attribute::Normal, normals.size()) &&
               matches(Attribute::Color, colors.size()) &&
               matches(Attribute::Intensity, intensities.size());
    }

    // Empties the batch but keeps capacity, so a reader reuses one batch for the whole file.
    void clear() {
        positions.clear();
        normals.clear();
        colors.clear();
        intensities.clear();
    }

    // Appends every point of `other`, which has the same attributes.
    void append(const PointBatch& other) {
        positions.insert(positions.end(), other.positions.begin(), other.positions.end());
        normals.insert(normals.end(), other.normals.begin(), other.normals.end());
        colors.insert(colors.end(), other.colors.begin(), other.colors.end());
        intensities.insert(intensities.end(), other.intensities.begin(), other.intensities.end());
    }

    void reserve(std::size_t count) {
        positions.reserve(count);
        if (attributes.has(Attribute::Normal)) {
            normals.reserve(count);
        }
        if (attributes.has(Attribute::Color)) {
            colors.reserve(count);
        }
        if (attributes.has(Attribute::Intensity)) {
            intensities.reserve(count);
        }
    }
};

} // namespace omicron
