// The point model: a batch of points as structure of arrays.
//
// Positions are float in the cloud's unit cube (see CubeTransform for the way back to source
// units). Optional attributes are either absent (empty vector) or have one entry per point.
// Structure of arrays was chosen because the hot consumers (Morton coding, sorting, bounds)
// touch positions only; bench/morton_bench measures coding over SoA vs packed records.
#pragma once

#include "points/batch_allocator.hpp"

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
    // The LAS column (points/las_fields.hpp): classification, returns, flags, user data, scan
    // angle and point source ID, then GPS time, NIR and extra bytes where present.
    Las = 1u << 3,
    GpsTime = 1u << 4, // in the LAS column; only with Las
    Nir = 1u << 5,     // in the LAS column; only with Las
};

// A set of optional attributes, and the number of LAS extra bytes per point (only with Las).
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
    // The set bits() and extraBytes() describe (a file header's fields).
    static constexpr AttributeSet fromBits(std::uint8_t bits, std::uint16_t extraBytes) {
        AttributeSet set;
        set.m_bits = bits;
        set.m_extraBytes = extraBytes;
        return set;
    }
    constexpr std::uint16_t extraBytes() const { return m_extraBytes; }
    constexpr AttributeSet& setExtraBytes(std::uint16_t count) {
        m_extraBytes = count;
        return *this;
    }
    // Bytes of one point's LAS column (0 without Las): 8, then 8 GPS time, 2 NIR, extra bytes.
    constexpr std::size_t lasBytes() const {
        if (!has(Attribute::Las)) {
            return 0;
        }
        return 8 + (has(Attribute::GpsTime) ? 8 : 0) + (has(Attribute::Nir) ? 2 : 0) +
               m_extraBytes;
    }
    // GpsTime, Nir and extra bytes live in the LAS column: they need Las.
    constexpr bool valid() const {
        return has(Attribute::Las) ||
               (!has(Attribute::GpsTime) && !has(Attribute::Nir) && m_extraBytes == 0);
    }
    friend constexpr bool operator==(AttributeSet, AttributeSet) = default;

private:
    std::uint8_t m_bits = 0;
    std::uint16_t m_extraBytes = 0;
};

// Bytes of one point with `attributes` as the point model keeps it: position, then normal,
// colour, intensity and the LAS column where present (a PointBatch, an exact SortedCloud).
constexpr std::size_t pointBytes(AttributeSet attributes) {
    return sizeof(glm::vec3) + (attributes.has(Attribute::Normal) ? sizeof(glm::vec3) : 0) +
           (attributes.has(Attribute::Color) ? sizeof(glm::u8vec3) : 0) +
           (attributes.has(Attribute::Intensity) ? sizeof(std::uint16_t) : 0) +
           attributes.lasBytes();
}

struct PointBatch {
    AttributeSet attributes; // which optional vectors below are filled (one entry per point)
    BatchColumn<glm::vec3> positions; // unit cube
    BatchColumn<glm::vec3> normals;   // unit length where the source had them; may be (0,0,0)
    BatchColumn<glm::u8vec3> colors;
    BatchColumn<std::uint16_t> intensities;
    BatchColumn<std::uint8_t> las; // attributes.lasBytes() bytes per point

    std::size_t size() const { return positions.size(); }
    bool empty() const { return positions.empty(); }

    // True when every present attribute has exactly one entry per point.
    bool consistent() const {
        const auto matches = [&](Attribute a, std::size_t n) {
            return attributes.has(a) ? n == size() : n == 0;
        };
        return matches(Attribute::Normal, normals.size()) &&
               matches(Attribute::Color, colors.size()) &&
               matches(Attribute::Intensity, intensities.size()) &&
               las.size() == size() * attributes.lasBytes();
    }

    // Empties the batch but keeps capacity, so a reader reuses one batch for the whole file.
    void clear() {
        positions.clear();
        normals.clear();
        colors.clear();
        intensities.clear();
        las.clear();
    }

    // Appends every point of `other`, which has the same attributes.
    void append(const PointBatch& other) {
        positions.insert(positions.end(), other.positions.begin(), other.positions.end());
        normals.insert(normals.end(), other.normals.begin(), other.normals.end());
        colors.insert(colors.end(), other.colors.begin(), other.colors.end());
        intensities.insert(intensities.end(), other.intensities.begin(), other.intensities.end());
        las.insert(las.end(), other.las.begin(), other.las.end());
    }

    // Appends points [begin, end) of `other`, which has the same attributes.
    void appendRange(const PointBatch& other, std::size_t begin, std::size_t end) {
        const auto slice = [&](const auto& from, auto& to, std::size_t stride) {
            if (!from.empty()) {
                to.insert(to.end(), from.begin() + static_cast<std::ptrdiff_t>(begin * stride),
                          from.begin() + static_cast<std::ptrdiff_t>(end * stride));
            }
        };
        slice(other.positions, positions, 1);
        slice(other.normals, normals, 1);
        slice(other.colors, colors, 1);
        slice(other.intensities, intensities, 1);
        slice(other.las, las, other.attributes.lasBytes());
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
        las.reserve(count * attributes.lasBytes());
    }
};

} // namespace omicron
