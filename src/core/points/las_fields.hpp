// The LAS attributes of a point beyond position, colour and intensity, kept as one byte column
// (PointBatch::las, SortedCloud::lasRecord) whose layout the cloud's AttributeSet gives:
//
//   u8  classification   ASPRS class (LAS 1.4: 0-255; formats 0-5: the low 5 bits)
//   u8  returns          return number (low nibble) | number of returns (high nibble)
//   u8  flags            bits 0-3 classification flags (synthetic, key-point, withheld, overlap),
//                        4-5 scanner channel, 6 scan direction, 7 edge of flight line
//   u8  user data
//   i16 scan angle       in 0.006 degree steps (LAS 1.4's unit; a format 0-5 rank of whole
//                        degrees d is stored as round(d / 0.006) and written back exactly)
//   u16 point source ID
//   [f64 GPS time]       Attribute::GpsTime
//   [u16 NIR]            Attribute::Nir
//   [extra bytes]        AttributeSet::extraBytes() bytes, as the file had them
//
// One column rather than one array per field: the sorter, the stores and the file formats move
// it as opaque bytes of a fixed stride, and only the reader, the writer and the viewer look
// inside. The fields keep the file's values bit for bit, so a LAS 1.4 export writes them back.
#pragma once

#include "points/point_batch.hpp"

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace omicron {

struct LasFields {
    std::uint8_t classification = 0;
    std::uint8_t returns = 0; // returnNumber() | numberOfReturns() << 4
    std::uint8_t flags = 0;
    std::uint8_t userData = 0;
    std::int16_t scanAngle = 0; // 0.006 degrees
    std::uint16_t pointSourceId = 0;
    double gpsTime = 0.0;   // 0 where the cloud has none
    std::uint16_t nir = 0;  // 0 where the cloud has none

    int returnNumber() const { return returns & 0x0f; }
    int numberOfReturns() const { return returns >> 4; }
    double scanAngleDegrees() const { return scanAngle * 0.006; }
};

// Flag bits of LasFields::flags.
namespace las_flag {
inline constexpr std::uint8_t kSynthetic = 1u << 0;
inline constexpr std::uint8_t kKeyPoint = 1u << 1;
inline constexpr std::uint8_t kWithheld = 1u << 2;
inline constexpr std::uint8_t kOverlap = 1u << 3;
inline constexpr int kScannerChannelShift = 4; // 2 bits
inline constexpr std::uint8_t kScanDirection = 1u << 6;
inline constexpr std::uint8_t kEdgeOfFlightLine = 1u << 7;
} // namespace las_flag

// Where the fields sit in one point's LAS column bytes.
struct LasColumnLayout {
    static constexpr std::size_t kBaseBytes = 8;
    // The column without extra bytes at its largest: base, GPS time, NIR.
    static constexpr std::size_t kMaxFieldBytes = kBaseBytes + 8 + 2;
    std::size_t gpsTimeOffset = 0; // valid when the attribute is present
    std::size_t nirOffset = 0;
    std::size_t extraOffset = 0;
    std::size_t extraBytes = 0;
    std::size_t bytes = 0; // 0: the cloud has no LAS column

    static constexpr LasColumnLayout of(AttributeSet attributes) {
        LasColumnLayout layout;
        if (!attributes.has(Attribute::Las)) {
            return layout;
        }
        std::size_t at = kBaseBytes;
        if (attributes.has(Attribute::GpsTime)) {
            layout.gpsTimeOffset = at;
            at += sizeof(double);
        }
        if (attributes.has(Attribute::Nir)) {
            layout.nirOffset = at;
            at += sizeof(std::uint16_t);
        }
        layout.extraOffset = at;
        layout.extraBytes = attributes.extraBytes();
        layout.bytes = attributes.lasBytes();
        return layout;
    }
};

// Reads the fields of one point's column bytes (extra bytes stay where they are).
inline LasFields decodeLasFields(AttributeSet attributes, const std::uint8_t* bytes) {
    const LasColumnLayout layout = LasColumnLayout::of(attributes);
    LasFields fields;
    fields.classification = bytes[0];
    fields.returns = bytes[1];
    fields.flags = bytes[2];
    fields.userData = bytes[3];
    std::memcpy(&fields.scanAngle, bytes + 4, 2);
    std::memcpy(&fields.pointSourceId, bytes + 6, 2);
    if (attributes.has(Attribute::GpsTime)) {
        std::memcpy(&fields.gpsTime, bytes + layout.gpsTimeOffset, sizeof(double));
    }
    if (attributes.has(Attribute::Nir)) {
        std::memcpy(&fields.nir, bytes + layout.nirOffset, sizeof(std::uint16_t));
    }
    return fields;
}

// Writes the fields into one point's column bytes (extra bytes untouched).
inline void encodeLasFields(AttributeSet attributes, const LasFields& fields,
                            std::uint8_t* bytes) {
    const LasColumnLayout layout = LasColumnLayout::of(attributes);
    bytes[0] = fields.classification;
    bytes[1] = fields.returns;
    bytes[2] = fields.flags;
    bytes[3] = fields.userData;
    std::memcpy(bytes + 4, &fields.scanAngle, 2);
    std::memcpy(bytes + 6, &fields.pointSourceId, 2);
    if (attributes.has(Attribute::GpsTime)) {
        std::memcpy(bytes + layout.gpsTimeOffset, &fields.gpsTime, sizeof(double));
    }
    if (attributes.has(Attribute::Nir)) {
        std::memcpy(bytes + layout.nirOffset, &fields.nir, sizeof(std::uint16_t));
    }
}

} // namespace omicron
