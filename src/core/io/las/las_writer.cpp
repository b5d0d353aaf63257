#include "io/las/las_writer.hpp"

#include "io/las/las_header.hpp"

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

template <typename T> void store(std::uint8_t* bytes, const T& value) {
    std::memcpy(bytes, &value, sizeof value);
}

void storeText(std::uint8_t* bytes, std::size_t capacity, const std::string& text) {
    std::memcpy(bytes, text.data(), std::min(capacity, text.size()));
}

std::string number(double value) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

class LasFileWriter {
public:
    LasFileWriter(const std::string& path, const PointBatch& points, const CubeTransform& cube,
                  const LasWriteOptions& options)
        : m_path(path), m_points(points), m_cube(cube), m_options(options) {}

    void write() {
        checkOptions();
        const Bounds quantised = quantisedBounds();
        AtomicFileWriter file(m_path);
        writeHeader(file, quantised);
        writeVlrs(file);
        writeRecords(file);
        file.commit();
    }

private:
    [[noreturn]] void fail(const std::string& why) const { throw OutputError(m_path + ": " + why); }

    std::uint16_t recordLength() const {
        return static_cast<std::uint16_t>(las::minimumRecordLength(m_options.pointFormat) +
                                          m_options.extraBytesPerRecord);
    }

    std::uint32_t pointDataOffset() const {
        std::uint64_t offset = las::requiredHeaderSize(m_options.versionMinor);
        for (const LasVariableLengthRecord& vlr : m_options.vlrs) {
            offset += las::kVlrHeaderSize + vlr.payload.size();
        }
        return static_cast<std::uint32_t>(offset);
    }

    void checkOptions() const {
        const LasWriteOptions& o = m_options;
        if (o.versionMinor != 2 && o.versionMinor != 4) {
            fail("cannot write LAS 1." + std::to_string(o.versionMinor) +
                 ", expected version 1.2 or 1.4");
        }
        if (o.pointFormat > las::kMaxPointFormat) {
            fail("unknown LAS point format " + std::to_string(o.pointFormat) +
                 ", expected 0 to 10");
        }
        if (o.pointFormat > 5 && o.versionMinor < 4) {
            fail("LAS point format " + std::to_string(o.pointFormat) + " needs LAS 1.4");
        }
        if (las::minimumRecordLength(o.pointFormat) + o.extraBytesPerRecord > 0xFFFF) {
            fail(std::to_string(o.extraBytesPerRecord) +
                 " extra bytes make the record longer than 65535 bytes");
        }
        for (int axis = 0; axis < 3; ++axis) {
            if (!std::isfinite(o.scale[axis]) || !(o.scale[axis] > 0.0)) {
                fail("LAS scale " + number(o.scale[axis]) + " is not a finite positive number");
            }
            if (!std::isfinite(o.offset[axis])) {
                fail("LAS offset " + number(o.offset[axis]) + " is not finite");
            }
        }
        for (const LasVariableLengthRecord& vlr : o.vlrs) {
            if (vlr.userId.size() > 16 || vlr.description.size() > 32 ||
                vlr.payload.size() > 0xFFFF) {
                fail("variable length record '" + vlr.userId +
                     "' exceeds the LAS limits (user id 16 characters, description 32, "
                     "payload 65535 bytes)");
            }
        }
        if (pointDataOffset() >= std::numeric_limits<std::uint32_t>::max()) {
            fail("the variable length records do not fit before a 32-bit point data offset");
        }
        if (o.versionMinor < 4 && m_points.size() > std::numeric_limits<std::uint32_t>::max()) {
            fail(std::to_string(m_points.size()) +
                 " points do not fit in LAS 1.2's 32-bit point count; write LAS 1.4");
        }
    }

    // The stored integers of point `index`; checked to fit by quantisedBounds().
    glm::dvec3 quantise(std::size_t index) const {
        const glm::dvec3 source = m_cube.toSource(m_points.positions[index]);
        return glm::round((source - m_options.offset) / m_options.scale);
    }

    Bounds quantisedBounds() const {
        constexpr double lowest = std::numeric_limits<std::int32_t>::min();
        constexpr double highest = std::numeric_limits<std::int32_t>::max();
        Bounds steps;
        for (std::size_t i = 0; i < m_points.size(); ++i) {
            const glm::dvec3 q = quantise(i);
            for (int axis = 0; axis < 3; ++axis) {
                if (!(q[axis] >= lowest && q[axis] <= highest)) {
                    fail("point " + std::to_string(i) +
                         " does not fit in LAS's 32-bit integer "
                         "coordinates with scale " +
                         number(m_options.scale[axis]) + " and offset " +
                         number(m_options.offset[axis]) +
                         "; use a larger scale or an offset near the data");
                }
            }
            steps.extend(q);
        }
        if (steps.empty()) {
            return Bounds{glm::dvec3(0.0), glm::dvec3(0.0)};
        }
        return {steps.min * m_options.scale + m_options.offset,
                steps.max * m_options.scale + m_options.offset};
    }

    void writeHeader(AtomicFileWriter& file, const Bounds& bounds) const {
        namespace field = las::field;
        const LasWriteOptions& o = m_options;
        const std::uint16_t headerSize = las::requiredHeaderSize(o.versionMinor);
        const std::uint64_t count = m_points.size();
        std::array<std::uint8_t, las::kHeaderSize14> header{};
        std::memcpy(&header[field::signature], "LASF", 4);
        if (o.pointFormat > 5) {
            store<std::uint16_t>(&header[field::globalEncoding], kGlobalEncodingWkt);
        }
        header[field::versionMajor] = 1;
        header[field::versionMinor] = o.versionMinor;
        storeText(&header[field::systemIdentifier], 32, "OTHER");
        storeText(&header[field::generatingSoftware], 32, "omicron");
        store<std::uint16_t>(&header[field::headerSize], headerSize);
        store<std::uint32_t>(&header[field::pointDataOffset], pointDataOffset());
        store<std::uint32_t>(&header[field::vlrCount], static_cast<std::uint32_t>(o.vlrs.size()));
        header[field::pointFormat] = o.pointFormat;
        store<std::uint16_t>(&header[field::recordLength], recordLength());
        // LAS 1.4 leaves the legacy counts 0 for formats 6 to 10 and for counts over 2^32.
        const bool legacyCountFits =
            o.pointFormat <= 5 && count <= std::numeric_limits<std::uint32_t>::max();
        if (legacyCountFits) {
            store<std::uint32_t>(&header[field::legacyPointCount],
                                 static_cast<std::uint32_t>(count));
            store<std::uint32_t>(&header[field::legacyPointsByReturn],
                                 static_cast<std::uint32_t>(count));
        }
        for (int axis = 0; axis < 3; ++axis) {
            store<double>(&header[field::scale + 8 * axis], o.scale[axis]);
            store<double>(&header[field::offset + 8 * axis], o.offset[axis]);
            store<double>(&header[field::bounds + 16 * axis], bounds.max[axis]);
            store<double>(&header[field::bounds + 16 * axis + 8], bounds.min[axis]);
        }
        if (o.versionMinor >= 4) {
            store<std::uint64_t>(&header[field::pointCount], count);
            store<std::uint64_t>(&header[field::pointsByReturn], count);
        }
        file.write(header.data(), headerSize);
    }

    void writeVlrs(AtomicFileWriter& file) const {
        for (const LasVariableLengthRecord& vlr : m_options.vlrs) {
            std::array<std::uint8_t, las::kVlrHeaderSize> bytes{};
            storeText(&bytes[2], 16, vlr.userId);
            store<std::uint16_t>(&bytes[18], vlr.recordId);
            store<std::uint16_t>(&bytes[20], static_cast<std::uint16_t>(vlr.payload.size()));
            storeText(&bytes[22], 32, vlr.description);
            file.write(bytes.data(), bytes.size());
            file.write(vlr.payload.data(), vlr.payload.size());
        }
    }

    void writeRecords(AtomicFileWriter& file) const {
        const std::uint8_t format = m_options.pointFormat;
        const std::size_t stride = recordLength();
        const bool hasIntensity = m_points.attributes.has(Attribute::Intensity);
        const bool writesColor =
            las::formatHasColor(format) && m_points.attributes.has(Attribute::Color);
        const std::size_t colorAt = writesColor ? las::colorOffset(format) : 0;
        const std::uint8_t returnBits = format > 5 ? kSingleReturn14 : kSingleReturnLegacy;

        std::vector<std::uint8_t> chunk;
        for (std::size_t first = 0; first < m_points.size(); first += kChunkRecords) {
            const std::size_t count = std::min(kChunkRecords, m_points.size() - first);
            chunk.assign(count * stride, 0);
            for (std::size_t i = 0; i < count; ++i) {
                const std::size_t index = first + i;
                std::uint8_t* record = &chunk[i * stride];
                const glm::dvec3 q = quantise(index);
                store(record, static_cast<std::int32_t>(q.x));
                store(record + 4, static_cast<std::int32_t>(q.y));
                store(record + 8, static_cast<std::int32_t>(q.z));
                if (hasIntensity) {
                    store(record + las::kRecordIntensity, m_points.intensities[index]);
                }
                record[las::kRecordReturnBits] = returnBits;
                if (writesColor) {
                    const glm::u8vec3 c = m_points.colors[index];
                    store(record + colorAt, static_cast<std::uint16_t>(c.r * 257));
                    store(record + colorAt + 2, static_cast<std::uint16_t>(c.g * 257));
                    store(record + colorAt + 4, static_cast<std::uint16_t>(c.b * 257));
                }
            }
            file.write(chunk.data(), chunk.size());
        }
    }

    const std::string& m_path;
    const PointBatch& m_points;
    const CubeTransform& m_cube;
    const LasWriteOptions& m_options;
};

} // namespace

void writeLas(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const LasWriteOptions& options) {
    assert(points.consistent());
    LasFileWriter(path, points, cube, options).write();
}

} // namespace omicron
