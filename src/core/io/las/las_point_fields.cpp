#include "io/las/las_point_fields.hpp"

#include "io/las/las_header.hpp"
#include "io/raw_bytes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace omicron::las {

namespace {

// Record offsets after X, Y, Z (12 bytes) and intensity (2) in the two layouts.
namespace legacy {
constexpr std::size_t kReturns = 14;   // return number 0-2, count 3-5, direction 6, edge 7
constexpr std::size_t kClass = 15;     // class 0-4, synthetic 5, key-point 6, withheld 7
constexpr std::size_t kScanRank = 16;  // int8, whole degrees
constexpr std::size_t kUserData = 17;
constexpr std::size_t kSourceId = 18;
constexpr std::size_t kGpsTime = 20;
} // namespace legacy
namespace v14 {
constexpr std::size_t kReturns = 14;   // return number 0-3, count 4-7
constexpr std::size_t kFlags = 15;     // class flags 0-3, channel 4-5, direction 6, edge 7
constexpr std::size_t kClass = 16;
constexpr std::size_t kUserData = 17;
constexpr std::size_t kScanAngle = 18; // int16, 0.006 degrees
constexpr std::size_t kSourceId = 20;
constexpr std::size_t kGpsTime = 22;
constexpr std::size_t kNir = 36;       // formats 8 and 10
} // namespace v14

// 1 / 0.006: steps of the LAS 1.4 scan angle per degree.
constexpr double kScanStepsPerDegree = 1000.0 / 6.0;

} // namespace

bool formatHasGpsTime(std::uint8_t pointFormat) {
    return pointFormat == 1 || (pointFormat >= 3 && pointFormat <= kMaxPointFormat);
}

bool formatHasNir(std::uint8_t pointFormat) {
    return pointFormat == 8 || pointFormat == 10;
}

bool formatHasWaveform(std::uint8_t pointFormat) {
    return pointFormat == 4 || pointFormat == 5 || pointFormat == 9 || pointFormat == 10;
}

AttributeSet attributesOfFormat(std::uint8_t pointFormat, std::uint16_t recordLength) {
    AttributeSet attributes = AttributeSet(Attribute::Intensity) | Attribute::Las;
    if (formatHasColor(pointFormat)) {
        attributes.add(Attribute::Color);
    }
    if (formatHasGpsTime(pointFormat)) {
        attributes.add(Attribute::GpsTime);
    }
    if (formatHasNir(pointFormat)) {
        attributes.add(Attribute::Nir);
    }
    const int extra = int{recordLength} - int{minimumRecordLength(pointFormat)};
    attributes.setExtraBytes(static_cast<std::uint16_t>(std::max(extra, 0)));
    return attributes;
}

namespace {

// Whole degrees of a legacy scan angle rank (the byte as stored) in LAS 1.4's 0.006 degree
// steps, from a table: no rounding per point.
const std::array<std::int16_t, 256>& rankSteps() {
    static const std::array<std::int16_t, 256> kRankSteps = [] {
        std::array<std::int16_t, 256> steps{};
        for (int byte = 0; byte < 256; ++byte) {
            steps[static_cast<std::size_t>(byte)] = static_cast<std::int16_t>(
                std::lround(static_cast<std::int8_t>(byte) * kScanStepsPerDegree));
        }
        return steps;
    }();
    return kRankSteps;
}

// Legacy fields mapped onto LAS 1.4's: 3-bit returns to nibbles, the class byte's flags to the
// flags byte, the scan angle rank to 0.006 degree steps.
template <bool GpsTime>
void readLegacyColumn(const std::uint8_t* record, const LasColumnLayout& layout,
                      const std::array<std::int16_t, 256>& steps, std::uint8_t* column) {
    const std::uint8_t returns = record[legacy::kReturns];
    const std::uint8_t classByte = record[legacy::kClass];
    column[0] = classByte & 0x1f;
    column[1] = static_cast<std::uint8_t>((returns & 0x07) | ((returns >> 3) & 0x07) << 4);
    column[2] = static_cast<std::uint8_t>((classByte >> 5) | (returns & 0xc0));
    column[3] = record[legacy::kUserData];
    storeRaw(column + 4, steps[record[legacy::kScanRank]]);
    std::memcpy(column + 6, record + legacy::kSourceId, 2);
    if constexpr (GpsTime) {
        std::memcpy(column + layout.gpsTimeOffset, record + legacy::kGpsTime, 8);
    }
}

// LAS 1.4's returns and flags bytes are the column's; class and user data follow.
template <bool Nir>
void readV14Column(const std::uint8_t* record, const LasColumnLayout& layout,
                   std::uint8_t* column) {
    column[0] = record[v14::kClass];
    column[1] = record[v14::kReturns];
    column[2] = record[v14::kFlags];
    column[3] = record[v14::kUserData];
    std::memcpy(column + 4, record + v14::kScanAngle, 4); // scan angle, point source ID
    std::memcpy(column + layout.gpsTimeOffset, record + v14::kGpsTime, 8);
    if constexpr (Nir) {
        std::memcpy(column + layout.nirOffset, record + v14::kNir, 2);
    }
}

// The standard fields of each record by `read`, then the extra bytes where there are any.
template <typename Read>
void readColumns(const std::uint8_t* records, std::size_t count, std::size_t stride,
                 std::uint8_t pointFormat, const LasColumnLayout& layout, std::uint8_t* columns,
                 Read read) {
    for (std::size_t i = 0; i < count; ++i) {
        read(records + i * stride, columns + i * layout.bytes);
    }
    if (layout.extraBytes != 0) {
        const std::size_t standard = minimumRecordLength(pointFormat);
        for (std::size_t i = 0; i < count; ++i) {
            std::memcpy(columns + i * layout.bytes + layout.extraOffset,
                        records + i * stride + standard, layout.extraBytes);
        }
    }
}

} // namespace

void readLasColumns(const std::uint8_t* records, std::size_t count, std::size_t stride,
                    std::uint8_t pointFormat, const LasColumnLayout& layout,
                    std::uint8_t* columns) {
    const auto run = [&](auto read) {
        readColumns(records, count, stride, pointFormat, layout, columns, read);
    };
    if (pointFormat <= 5) {
        const std::array<std::int16_t, 256>& steps = rankSteps();
        if (layout.gpsTimeOffset != 0) {
            run([&](const std::uint8_t* r, std::uint8_t* c) {
                readLegacyColumn<true>(r, layout, steps, c);
            });
        } else {
            run([&](const std::uint8_t* r, std::uint8_t* c) {
                readLegacyColumn<false>(r, layout, steps, c);
            });
        }
    } else if (layout.nirOffset != 0) {
        run([&](const std::uint8_t* r, std::uint8_t* c) { readV14Column<true>(r, layout, c); });
    } else {
        run([&](const std::uint8_t* r, std::uint8_t* c) { readV14Column<false>(r, layout, c); });
    }
}

void readLasColumn(const std::uint8_t* record, std::uint8_t pointFormat,
                   const LasColumnLayout& layout, std::uint8_t* column) {
    readLasColumns(record, 1, 0, pointFormat, layout, column);
}

LasFields readLasFields(const std::uint8_t* record, std::uint8_t pointFormat) {
    // The fields alone: a layout without extra bytes, whatever the record holds after them.
    const AttributeSet attributes = attributesOfFormat(pointFormat, minimumRecordLength(pointFormat));
    const LasColumnLayout layout = LasColumnLayout::of(attributes);
    std::array<std::uint8_t, LasColumnLayout::kMaxFieldBytes> column{};
    readLasColumn(record, pointFormat, layout, column.data());
    return decodeLasFields(attributes, column.data());
}

void writeLasFields(const LasFields& fields, std::uint8_t pointFormat, std::uint8_t* record) {
    if (pointFormat <= 5) {
        const int number = std::min(fields.returnNumber(), 7);
        const int count = std::min(fields.numberOfReturns(), 7);
        record[legacy::kReturns] =
            static_cast<std::uint8_t>(number | count << 3 | (fields.flags & 0xc0));
        record[legacy::kClass] = static_cast<std::uint8_t>(
            std::min<int>(fields.classification, 31) | (fields.flags & 0x07) << 5);
        const long degrees = std::lround(fields.scanAngleDegrees());
        storeRaw(record + legacy::kScanRank, static_cast<std::int8_t>(std::clamp(degrees, -90L, 90L)));
        record[legacy::kUserData] = fields.userData;
        storeRaw(record + legacy::kSourceId, fields.pointSourceId);
        if (formatHasGpsTime(pointFormat)) {
            storeRaw(record + legacy::kGpsTime, fields.gpsTime);
        }
        return;
    }
    record[v14::kReturns] = fields.returns;
    record[v14::kFlags] = fields.flags;
    record[v14::kClass] = fields.classification;
    record[v14::kUserData] = fields.userData;
    storeRaw(record + v14::kScanAngle, fields.scanAngle);
    storeRaw(record + v14::kSourceId, fields.pointSourceId);
    storeRaw(record + v14::kGpsTime, fields.gpsTime);
    if (formatHasNir(pointFormat)) {
        storeRaw(record + v14::kNir, fields.nir);
    }
}

} // namespace omicron::las
