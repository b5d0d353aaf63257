// Fixed-size binary records of one point: its unit-cube position and attributes packed as
// x y z [nx ny nz] [r g b] [intensity] [LAS column] (host floats, little-endian), absent
// attributes taking no bytes. The record of a .oms sorted stream and of the sorter's scratch
// runs. Either may leave out an intensity or LAS column every point of it shares (a uniform
// column, kept once beside the records): the layout says which are stored.
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
    bool intensity = false; // stored at intensityOffset
    std::size_t intensityOffset = 0;
    std::size_t lasOffset = 0;
    std::size_t lasBytes = 0; // stored at lasOffset; 0: none
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
            layout.intensity = true;
            layout.intensityOffset = at;
            at += sizeof(std::uint16_t);
        }
        layout.lasOffset = at;
        layout.lasBytes = attributes.lasBytes();
        at += layout.lasBytes;
        layout.bytes = at;
        return layout;
    }

    // This layout without its intensity and/or LAS column (which are then kept elsewhere).
    constexpr PointRecordLayout without(bool leaveOutIntensity, bool leaveOutLas) const {
        PointRecordLayout layout = *this;
        if (leaveOutIntensity && intensity) {
            layout.intensity = false;
            layout.intensityOffset = 0;
            layout.lasOffset -= sizeof(std::uint16_t);
            layout.bytes -= sizeof(std::uint16_t);
        }
        if (leaveOutLas) {
            layout.bytes -= layout.lasBytes;
            layout.lasBytes = 0;
        }
        return layout;
    }
};

// The values of the columns a layout leaves out, for decoding its records into a batch that
// has them.
struct LeftOutColumns {
    std::uint16_t intensity = 0;
    const std::uint8_t* lasRecord = nullptr; // the batch's lasBytes() bytes
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
    if (layout.intensity) {
        std::memcpy(record + layout.intensityOffset, &points.intensities[index],
                    sizeof(std::uint16_t));
    }
    if (layout.lasBytes != 0) {
        std::memcpy(record + layout.lasOffset, points.las.data() + index * layout.lasBytes,
                    layout.lasBytes);
    }
}

// Appends the point stored in `record` to `points` (whose attributes give the layout), with
// `leftOut`'s value for a column the layout leaves out.
inline void decodePointRecord(const PointRecordLayout& layout, const std::uint8_t* record,
                              PointBatch& points, const LeftOutColumns& leftOut = {}) {
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
    if (layout.intensity) {
        std::uint16_t intensity;
        std::memcpy(&intensity, record + layout.intensityOffset, sizeof intensity);
        points.intensities.push_back(intensity);
    } else if (points.attributes.has(Attribute::Intensity)) {
        points.intensities.push_back(leftOut.intensity);
    }
    if (layout.lasBytes != 0) {
        points.las.insert(points.las.end(), record + layout.lasOffset,
                          record + layout.lasOffset + layout.lasBytes);
    } else if (const std::size_t lasBytes = points.attributes.lasBytes(); lasBytes != 0) {
        points.las.insert(points.las.end(), leftOut.lasRecord, leftOut.lasRecord + lasBytes);
    }
}

} // namespace omicron
