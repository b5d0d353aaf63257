#include "io/las/las_writer.hpp"

#include "io/las/las_header.hpp"
#include "io/las/las_point_fields.hpp"
#include "io/raw_bytes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

static_assert(std::endian::native == std::endian::little,
              "LAS fields are little-endian and are stored with memcpy");

namespace omicron {

namespace {

// Records are assembled in chunks of this many before they go to the file.
constexpr std::size_t kChunkRecords = 16384;

// Return number 1 of 1: bits 0-2 and 3-5 in formats 0 to 5, bits 0-3 and 4-7 in 6 to 10.
constexpr std::uint8_t kSingleReturnLegacy = 0x09;
constexpr std::uint8_t kSingleReturn14 = 0x11;

// LAS 1.4 requires a WKT coordinate system (global encoding bit 4) for formats 6 to 10.
constexpr std::uint16_t kGlobalEncodingWkt = 1u << 4;

void storeText(std::uint8_t* bytes, std::size_t capacity, const std::string& text) {
    std::memcpy(bytes, text.data(), std::min(capacity, text.size()));
}

std::string number(double value) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

[[noreturn]] void fail(const std::string& path, const std::string& why) {
    throw OutputError(path + ": " + why);
}

std::uint16_t recordLength(const LasWriteOptions& options) {
    return static_cast<std::uint16_t>(las::minimumRecordLength(options.pointFormat) +
                                      options.extraBytesPerRecord);
}

std::uint32_t pointDataOffset(const LasWriteOptions& options) {
    std::uint64_t offset = las::requiredHeaderSize(options.versionMinor);
    for (const LasVariableLengthRecord& vlr : options.vlrs) {
        offset += las::kVlrHeaderSize + vlr.payload.size();
    }
    return static_cast<std::uint32_t>(offset);
}

void checkOptions(const std::string& path, const LasWriteOptions& o, std::uint64_t pointCount) {
    if (o.versionMinor != 2 && o.versionMinor != 4) {
        fail(path, "cannot write LAS 1." + std::to_string(o.versionMinor) +
                       ", expected version 1.2 or 1.4");
    }
    if (o.pointFormat > las::kMaxPointFormat) {
        fail(path, "unknown LAS point format " + std::to_string(o.pointFormat) +
                       ", expected 0 to 10");
    }
    if (o.pointFormat > 5 && o.versionMinor < 4) {
        fail(path, "LAS point format " + std::to_string(o.pointFormat) + " needs LAS 1.4");
    }
    if (las::minimumRecordLength(o.pointFormat) + o.extraBytesPerRecord > 0xFFFF) {
        fail(path, std::to_string(o.extraBytesPerRecord) +
                       " extra bytes make the record longer than 65535 bytes");
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (!std::isfinite(o.scale[axis]) || !(o.scale[axis] > 0.0)) {
            fail(path, "LAS scale " + number(o.scale[axis]) + " is not a finite positive number");
        }
        if (!std::isfinite(o.offset[axis])) {
            fail(path, "LAS offset " + number(o.offset[axis]) + " is not finite");
        }
    }
    for (const LasVariableLengthRecord& vlr : o.vlrs) {
        if (vlr.userId.size() > 16 || vlr.description.size() > 32 ||
            vlr.payload.size() > 0xFFFF) {
            fail(path, "variable length record '" + vlr.userId +
                           "' exceeds the LAS limits (user id 16 characters, description 32, "
                           "payload 65535 bytes)");
        }
    }
    if (pointDataOffset(o) >= std::numeric_limits<std::uint32_t>::max()) {
        fail(path, "the variable length records do not fit before a 32-bit point data offset");
    }
    if (o.versionMinor < 4 && pointCount > std::numeric_limits<std::uint32_t>::max()) {
        fail(path, std::to_string(pointCount) +
                       " points do not fit in LAS 1.2's 32-bit point count; write LAS 1.4");
    }
}

// The public header block; `bounds` in source units (those of the quantised coordinates).
std::vector<std::uint8_t> headerBytes(const LasWriteOptions& o, std::uint64_t count,
                                      const Bounds& bounds) {
    namespace field = las::field;
    const std::uint16_t headerSize = las::requiredHeaderSize(o.versionMinor);
    std::vector<std::uint8_t> header(las::kHeaderSize14, 0);
    std::memcpy(&header[field::signature], "LASF", 4);
    if (o.pointFormat > 5) {
        storeRaw<std::uint16_t>(&header[field::globalEncoding], kGlobalEncodingWkt);
    }
    header[field::versionMajor] = 1;
    header[field::versionMinor] = o.versionMinor;
    storeText(&header[field::systemIdentifier], 32, "OTHER");
    storeText(&header[field::generatingSoftware], 32, "omicron");
    storeRaw<std::uint16_t>(&header[field::headerSize], headerSize);
    storeRaw<std::uint32_t>(&header[field::pointDataOffset], pointDataOffset(o));
    storeRaw<std::uint32_t>(&header[field::vlrCount], static_cast<std::uint32_t>(o.vlrs.size()));
    header[field::pointFormat] = o.pointFormat;
    storeRaw<std::uint16_t>(&header[field::recordLength], recordLength(o));
    // LAS 1.4 leaves the legacy counts 0 for formats 6 to 10 and for counts over 2^32.
    const bool legacyCountFits =
        o.pointFormat <= 5 && count <= std::numeric_limits<std::uint32_t>::max();
    if (legacyCountFits) {
        storeRaw<std::uint32_t>(&header[field::legacyPointCount], static_cast<std::uint32_t>(count));
        storeRaw<std::uint32_t>(&header[field::legacyPointsByReturn],
                             static_cast<std::uint32_t>(count));
    }
    for (int axis = 0; axis < 3; ++axis) {
        storeRaw<double>(&header[field::scale + 8 * axis], o.scale[axis]);
        storeRaw<double>(&header[field::offset + 8 * axis], o.offset[axis]);
        storeRaw<double>(&header[field::bounds + 16 * axis], bounds.max[axis]);
        storeRaw<double>(&header[field::bounds + 16 * axis + 8], bounds.min[axis]);
    }
    if (o.versionMinor >= 4) {
        storeRaw<std::uint64_t>(&header[field::pointCount], count);
        storeRaw<std::uint64_t>(&header[field::pointsByReturn], count);
    }
    header.resize(headerSize);
    return header;
}

void writeVlrs(AtomicFileWriter& file, const LasWriteOptions& options) {
    for (const LasVariableLengthRecord& vlr : options.vlrs) {
        std::array<std::uint8_t, las::kVlrHeaderSize> bytes{};
        storeText(&bytes[2], 16, vlr.userId);
        storeRaw<std::uint16_t>(&bytes[18], vlr.recordId);
        storeRaw<std::uint16_t>(&bytes[20], static_cast<std::uint16_t>(vlr.payload.size()));
        storeText(&bytes[22], 32, vlr.description);
        file.write(bytes.data(), bytes.size());
        file.write(vlr.payload.data(), vlr.payload.size());
    }
}

} // namespace

LasStreamWriter::LasStreamWriter(const std::string& path, std::uint64_t pointCount,
                                 AttributeSet attributes, const LasWriteOptions& options)
    : m_options(options), m_attributes(attributes), m_pointCount(pointCount) {
    checkOptions(path, options, pointCount);
    m_file.emplace(path);
    // The bounds are known at finish(), which writes the header again.
    const std::vector<std::uint8_t> header = headerBytes(m_options, m_pointCount, Bounds{});
    m_file->write(header.data(), header.size());
    writeVlrs(*m_file, m_options);
}

void LasStreamWriter::append(const PointBatch& points, const CubeTransform& cube) {
    assert(points.consistent());
    const std::string& path = m_file->targetPath();
    if (points.attributes != m_attributes) {
        fail(path, "a batch's attributes differ from those the writer was opened with");
    }
    if (points.size() > m_pointCount - m_pointsWritten) {
        fail(path, std::to_string(m_pointsWritten + points.size()) +
                       " points appended, but the header declares " +
                       std::to_string(m_pointCount));
    }
    const std::uint8_t format = m_options.pointFormat;
    const std::size_t stride = recordLength(m_options);
    const bool hasIntensity = points.attributes.has(Attribute::Intensity);
    const bool writesColor = las::formatHasColor(format) && points.attributes.has(Attribute::Color);
    const std::size_t colorAt = writesColor ? las::colorOffset(format) : 0;
    const std::uint8_t returnBits = format > 5 ? kSingleReturn14 : kSingleReturnLegacy;
    const AttributeSet attributes = points.attributes;
    const LasColumnLayout lasLayout = LasColumnLayout::of(attributes);
    const std::size_t extraAt = las::minimumRecordLength(format);
    const std::size_t extraBytes =
        std::min<std::size_t>(lasLayout.extraBytes, m_options.extraBytesPerRecord);
    constexpr double lowest = std::numeric_limits<std::int32_t>::min();
    constexpr double highest = std::numeric_limits<std::int32_t>::max();

    for (std::size_t first = 0; first < points.size(); first += kChunkRecords) {
        const std::size_t count = std::min(kChunkRecords, points.size() - first);
        m_chunk.assign(count * stride, 0);
        for (std::size_t i = 0; i < count; ++i) {
            const std::size_t index = first + i;
            std::uint8_t* record = &m_chunk[i * stride];
            const glm::dvec3 source = cube.toSource(points.positions[index]);
            const glm::dvec3 q = glm::round((source - m_options.offset) / m_options.scale);
            for (int axis = 0; axis < 3; ++axis) {
                if (!(q[axis] >= lowest && q[axis] <= highest)) {
                    fail(path, "point " + std::to_string(m_pointsWritten + index) +
                                   " does not fit in LAS's 32-bit integer coordinates with "
                                   "scale " +
                                   number(m_options.scale[axis]) + " and offset " +
                                   number(m_options.offset[axis]) +
                                   "; use a larger scale or an offset near the data");
                }
            }
            m_steps.extend(q);
            storeRaw(record, static_cast<std::int32_t>(q.x));
            storeRaw(record + 4, static_cast<std::int32_t>(q.y));
            storeRaw(record + 8, static_cast<std::int32_t>(q.z));
            if (hasIntensity) {
                storeRaw(record + las::kRecordIntensity, points.intensities[index]);
            }
            if (lasLayout.bytes != 0) {
                const std::uint8_t* column = points.las.data() + index * lasLayout.bytes;
                las::writeLasFields(decodeLasFields(attributes, column), format, record);
                std::memcpy(record + extraAt, column + lasLayout.extraOffset, extraBytes);
            } else {
                record[las::kRecordReturnBits] = returnBits;
            }
            if (writesColor) {
                const glm::u8vec3 c = points.colors[index];
                storeRaw(record + colorAt, static_cast<std::uint16_t>(c.r * 257));
                storeRaw(record + colorAt + 2, static_cast<std::uint16_t>(c.g * 257));
                storeRaw(record + colorAt + 4, static_cast<std::uint16_t>(c.b * 257));
            }
        }
        m_file->write(m_chunk.data(), m_chunk.size());
    }
    m_pointsWritten += points.size();
}

void LasStreamWriter::finish() {
    if (m_pointsWritten != m_pointCount) {
        fail(m_file->targetPath(), "only " + std::to_string(m_pointsWritten) +
                                       " points appended, but the header declares " +
                                       std::to_string(m_pointCount));
    }
    // The header's bounds are those of the quantised coordinates, so a reader's check
    // against them is exact.
    const Bounds bounds = m_steps.empty()
                              ? Bounds{glm::dvec3(0.0), glm::dvec3(0.0)}
                              : Bounds{m_steps.min * m_options.scale + m_options.offset,
                                       m_steps.max * m_options.scale + m_options.offset};
    const std::vector<std::uint8_t> header = headerBytes(m_options, m_pointCount, bounds);
    m_file->writeAt(0, header.data(), header.size());
    m_file->commit();
}

std::vector<LasVariableLengthRecord> parseVariableLengthRecords(
    const std::vector<std::uint8_t>& stored) {
    std::vector<LasVariableLengthRecord> records;
    for (std::size_t at = 0; at + las::kVlrHeaderSize <= stored.size();) {
        const std::uint8_t* header = stored.data() + at;
        const auto length = loadRaw<std::uint16_t>(header + 20);
        if (at + las::kVlrHeaderSize + length > stored.size()) {
            break;
        }
        LasVariableLengthRecord record;
        record.userId = las::fixedLengthText(header + 2, 16);
        record.recordId = loadRaw<std::uint16_t>(header + 18);
        record.description = las::fixedLengthText(header + 22, 32);
        record.payload.assign(header + las::kVlrHeaderSize,
                              header + las::kVlrHeaderSize + length);
        records.push_back(std::move(record));
        at += las::kVlrHeaderSize + length;
    }
    return records;
}

LasVariableLengthRecord undocumentedExtraBytesRecord(std::uint16_t count) {
    // One 192-byte descriptor per run of up to 255 bytes: reserved[2], data type, options
    // (the byte count for type 0), name[32], then limits, scales and a description.
    constexpr std::size_t kDescriptorBytes = 192;
    LasVariableLengthRecord vlr;
    vlr.userId = "LASF_Spec";
    vlr.recordId = 4;
    vlr.description = "Extra Bytes Record";
    for (int first = 0, part = 0; first < count; first += 255, ++part) {
        std::array<std::uint8_t, kDescriptorBytes> descriptor{};
        descriptor[3] = static_cast<std::uint8_t>(std::min(255, count - first));
        storeText(&descriptor[4], 32, "extra " + std::to_string(part));
        storeText(&descriptor[160], 32, "carried through by omicron");
        vlr.payload.insert(vlr.payload.end(), descriptor.begin(), descriptor.end());
    }
    return vlr;
}

void writeLas(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const LasWriteOptions& options) {
    LasStreamWriter writer(path, points.size(), points.attributes, options);
    writer.append(points, cube);
    writer.finish();
}

} // namespace omicron
