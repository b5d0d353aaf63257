// Fixed-size binary records of one point: its unit-cube position and attributes packed as
// x y z [nx ny nz] [r g b] [intensity] [LAS column] (host floats, little-endian), absent
// attributes taking no bytes. The record of a .oms sorted stream and of the sorter's scratch runs.
#pragma once

#include "points/point_batch.hpp"

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace omicron {

static_assert(std::endian::native == std::endian::little, "point records are little-endian");

// Where each attribute sits inside a record; absent attributes have no bytes.
struct PointRecordLayout {
    std::size_t normalOffset = 0;
    std::size_t colorOffset = 0;
    std::size_t intensityOffset = 0;
    std::size_t lasOffset = 0;
    std::size_t lasBytes = 0;
    std::size_t bytes = 0;

    static constexpr PointRecordLayout of(AttributeSet attributes) {
        PointRecordLayout layout;
        std::size_t at = 3 * sizeof(float);
        if (attributes.has(Attribute::Normal)) {
            layout.normalOffset = at;
            at += 3 * sizeof(float);
        }
        if (attributes.has(Attribute::Color)) {
            layout.colorOffset = at;
            at += 3;
        }
        if (attributes.has(Attribute::Intensity)) {
            layout.intensityOffset = at;
            at += sizeof(std::uint16_t);
        }
        layout.lasOffset = at;
        layout.lasBytes = attributes.lasBytes();
        at += layout.lasBytes;
        layout.bytes = at;
        return layout;
    }
};

// Writes point `index` of `points` into `record` (layout.bytes bytes).
inline void encodePointRecord(const PointRecordLayout& layout, const PointBatch& points,
                              std::size_t index, std::uint8_t* record) {
    std::memcpy(record, &points.positions[index], 3 * sizeof(float));
    if (points.attributes.has(Attribute::Normal)) {
        std::memcpy(record + layout.normalOffset, &points.normals[index], 3 * sizeof(float));
    }
    if (points.attributes.has(Attribute::Color)) {
        std::memcpy(record + layout.colorOffset, &points.colors[index], 3);
    }
    if (points.attributes.has(Attribute::Intensity)) {
        std::memcpy(record + layout.intensityOffset, &points.intensities[index],
                    sizeof(std::uint16_t));
    }
    if (layout.lasBytes != 0) {
        std::memcpy(record + layout.lasOffset, points.las.data() + index * layout.lasBytes,
                    layout.lasBytes);
    }
}

// Appends the point stored in `record` to `points` (whose attributes give the layout).
inline void decodePointRecord(const PointRecordLayout& layout, const std::uint8_t* record,
                              PointBatch& points) {
    glm::vec3 position;
    std::memcpy(&position, record, 3 * sizeof(float));
    points.positions.push_back(position);
    if (points.attributes.has(Attribute::Normal)) {
        glm::vec3 normal;
        std::memcpy(&normal, record + layout.normalOffset, 3 * sizeof(float));
        points.normals.push_back(normal);
    }
    if (points.attributes.has(Attribute::Color)) {
        glm::u8vec3 color;
        std::memcpy(&color, record + layout.colorOffset, 3);
        points.colors.push_back(color);
    }
    if (points.attributes.has(Attribute::Intensity)) {
        std::uint16_t intensity;
        std::memcpy(&intensity, record + layout.intensityOffset, sizeof intensity);
        points.intensities.push_back(intensity);
    }
    if (layout.lasBytes != 0) {
        points.las.insert(points.las.end(), record + layout.lasOffset,
                          record + layout.lasOffset + layout.lasBytes);
    }
}

} // namespace omicron
