#include "io/las/las_header.hpp"

#include "io/input_error.hpp"
#include "io/raw_bytes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

static_assert(std::endian::native == std::endian::little,
              "LAS fields are little-endian and are loaded with memcpy");

namespace omicron::las {

namespace {

constexpr std::array<std::uint16_t, kMaxPointFormat + 1> kMinimumRecordLengths = {
    20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

// Red's offset per format, 0 for formats without colour.
constexpr std::array<std::uint8_t, kMaxPointFormat + 1> kColorOffsets = {0, 0,  20, 28, 0, 28,
                                                                         0, 30, 30, 0,  30};

std::string number(double value) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

// The signature as text, with unprintable bytes escaped, for the error message.
std::string printable(const std::uint8_t* bytes, std::size_t count) {
    std::string text;
    for (std::size_t i = 0; i < count; ++i) {
        if (bytes[i] >= 0x20 && bytes[i] < 0x7f) {
            text += static_cast<char>(bytes[i]);
        } else {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", bytes[i]);
            text += escaped;
        }
    }
    return text;
}

class HeaderParser {
public:
    explicit HeaderParser(FileStream& stream) : m_stream(stream) {}

    Header parse() {
        readBlock();
        checkVersion();
        checkHeaderSize();
        checkPointFormat();
        checkPointDataOffset();
        findLaszipRecord();
        checkRecordLength();
        checkScaleAndOffset();
        readPointCount();
        checkFileHoldsEveryRecord();
        readDeclaredBounds();
        return m_header;
    }

private:
    [[noreturn]] void fail(InputErrorKind kind, std::uint64_t byte, const std::string& detail) {
        throw InputError(kind, m_stream.path(), InputLocation::byte(byte), detail);
    }

    void readBlock() {
        m_stream.seek(0);
        m_available = m_stream.read(m_bytes.data(), m_bytes.size());
        if (m_available < 4 || std::memcmp(m_bytes.data(), "LASF", 4) != 0) {
            fail(InputErrorKind::MalformedHeader, field::signature,
                 "expected the LAS signature 'LASF', found '" +
                     printable(m_bytes.data(), std::min<std::size_t>(m_available, 4)) + "'");
        }
        requireBytes(kHeaderSize12, "LAS public header block");
    }

    // The file must hold `count` header bytes (checked before the fields are used).
    void requireBytes(std::size_t count, const std::string& what) {
        if (m_available < count) {
            fail(InputErrorKind::Truncated, m_available,
                 "expected the " + what + " (" + std::to_string(count) +
                     " bytes), but the file ends at byte " + std::to_string(m_available));
        }
    }

    void checkVersion() {
        const std::uint8_t major = m_bytes[field::versionMajor];
        const std::uint8_t minor = m_bytes[field::versionMinor];
        const std::string version = std::to_string(major) + "." + std::to_string(minor);
        if (major != 1) {
            fail(InputErrorKind::UnsupportedFeature, field::versionMajor,
                 "LAS version " + version + " is not supported, expected 1.0 to 1.4");
        }
        if (minor > 4) {
            fail(InputErrorKind::UnsupportedFeature, field::versionMinor,
                 "LAS version " + version + " is not supported, expected 1.0 to 1.4");
        }
        m_header.versionMinor = minor;
    }

    void checkHeaderSize() {
        const std::uint16_t required = requiredHeaderSize(m_header.versionMinor);
        m_header.headerSize = loadRaw<std::uint16_t>(&m_bytes[field::headerSize]);
        if (m_header.headerSize < required) {
            fail(InputErrorKind::MalformedHeader, field::headerSize,
                 "header size " + std::to_string(m_header.headerSize) + " is shorter than LAS 1." +
                     std::to_string(m_header.versionMinor) + " requires, expected at least " +
                     std::to_string(required) + " bytes");
        }
        requireBytes(required,
                     "LAS 1." + std::to_string(m_header.versionMinor) + " public header block");
    }

    void checkPointFormat() {
        const std::uint8_t byte = m_bytes[field::pointFormat];
        m_header.compressed = (byte & 0xC0) != 0;
        const std::uint8_t declared = byte & 0x3F;
        if (declared > kMaxPointFormat) {
            fail(InputErrorKind::MalformedHeader, field::pointFormat,
                 "unknown point data format " + std::to_string(declared) + ", expected 0 to 10");
        }
        m_header.pointFormat = declared;
    }

    void checkPointDataOffset() {
        m_header.pointDataOffset = loadRaw<std::uint32_t>(&m_bytes[field::pointDataOffset]);
        if (m_header.pointDataOffset < m_header.headerSize) {
            fail(InputErrorKind::MalformedHeader, field::pointDataOffset,
                 "offset to point data " + std::to_string(m_header.pointDataOffset) +
                     " lies inside the " + std::to_string(m_header.headerSize) +
                     "-byte header, expected at least " + std::to_string(m_header.headerSize));
        }
        if (m_header.pointDataOffset > m_stream.size()) {
            fail(InputErrorKind::MalformedHeader, field::pointDataOffset,
                 "offset to point data " + std::to_string(m_header.pointDataOffset) +
                     " lies beyond the end of the file, expected at most the file size " +
                     std::to_string(m_stream.size()));
        }
    }

    // LAZ writers set a compression bit in the format byte (or, rarely, leave it plain) and
    // always add the laszip VLR. The walk is lenient: it stops at the first record that does
    // not fit before the point data.
    void findLaszipRecord() {
        const bool bitSet = m_header.compressed;
        walkRecords();
        if (bitSet && m_header.laszipRecordOffset == 0) {
            fail(InputErrorKind::MalformedHeader, field::pointFormat,
                 "the point data format byte " + std::to_string(m_bytes[field::pointFormat]) +
                     " marks a LAZ (compressed) file, but the file has no 'laszip encoded' "
                     "variable length record (record id 22204) to say how it is compressed");
        }
    }

    void walkRecords() {
        const std::uint32_t vlrCount = loadRaw<std::uint32_t>(&m_bytes[field::vlrCount]);
        std::uint64_t position = m_header.headerSize;
        std::array<std::uint8_t, kVlrHeaderSize> vlr{};
        for (std::uint32_t i = 0; i < vlrCount; ++i) {
            if (position + kVlrHeaderSize > m_header.pointDataOffset) {
                return;
            }
            m_stream.seek(position);
            m_stream.readExact(vlr.data(), vlr.size(), "a variable length record header");
            const char* userId = reinterpret_cast<const char*>(&vlr[2]);
            const std::uint16_t recordId = loadRaw<std::uint16_t>(&vlr[18]);
            const std::uint16_t length = loadRaw<std::uint16_t>(&vlr[20]);
            if (recordId == kLaszipRecordId && std::strncmp(userId, "laszip encoded", 16) == 0 &&
                m_header.laszipRecordOffset == 0) {
                m_header.compressed = true;
                m_header.laszipRecordOffset = position + kVlrHeaderSize;
                m_header.laszipRecordLength = length;
            }
            const bool extraBytes = recordId == kExtraBytesRecordId &&
                                    std::strncmp(userId, "LASF_Spec", 16) == 0 &&
                                    position + kVlrHeaderSize + length <= m_header.pointDataOffset;
            const bool projection = std::strncmp(userId, "LASF_Projection", 16) == 0 &&
                                    position + kVlrHeaderSize + length <= m_header.pointDataOffset;
            if (projection) {
                const std::size_t at = m_header.projectionRecords.size();
                m_header.projectionRecords.resize(at + kVlrHeaderSize + length);
                std::memcpy(m_header.projectionRecords.data() + at, vlr.data(), kVlrHeaderSize);
                m_stream.readExact(m_header.projectionRecords.data() + at + kVlrHeaderSize, length,
                                   "a coordinate system record");
            }
            if (extraBytes) {
                const std::size_t at = m_header.extraBytesDescriptors.size();
                m_header.extraBytesDescriptors.resize(at + length);
                m_stream.readExact(m_header.extraBytesDescriptors.data() + at, length,
                                   "an Extra Bytes record");
            }
            position += kVlrHeaderSize + length;
        }
    }

    void checkRecordLength() {
        m_header.recordLength = loadRaw<std::uint16_t>(&m_bytes[field::recordLength]);
        const std::uint16_t minimum = minimumRecordLength(m_header.pointFormat);
        if (m_header.recordLength < minimum) {
            fail(InputErrorKind::MalformedHeader, field::recordLength,
                 "point record length " + std::to_string(m_header.recordLength) +
                     " is shorter than point format " + std::to_string(m_header.pointFormat) +
                     " requires, expected at least " + std::to_string(minimum) + " bytes");
        }
    }

    void checkScaleAndOffset() {
        const char* axes = "xyz";
        for (int axis = 0; axis < 3; ++axis) {
            const std::size_t scaleAt = field::scale + 8 * axis;
            const double scale = loadRaw<double>(&m_bytes[scaleAt]);
            if (!std::isfinite(scale) || scale == 0.0) {
                fail(InputErrorKind::MalformedHeader, scaleAt,
                     std::string(1, axes[axis]) + " scale factor is " + number(scale) +
                         ", expected a finite non-zero number");
            }
            const std::size_t offsetAt = field::offset + 8 * axis;
            const double offset = loadRaw<double>(&m_bytes[offsetAt]);
            if (!std::isfinite(offset)) {
                fail(InputErrorKind::MalformedHeader, offsetAt,
                     std::string(1, axes[axis]) + " offset is " + number(offset) +
                         ", expected a finite number");
            }
            m_header.scale[axis] = scale;
            m_header.offset[axis] = offset;
        }
    }

    // LAS 1.4 keeps the legacy 32-bit count for old readers and may leave it 0; the 64-bit
    // count is the real one. Some writers fill only the legacy count, so a 0 there falls back.
    void readPointCount() {
        const std::uint64_t legacy = loadRaw<std::uint32_t>(&m_bytes[field::legacyPointCount]);
        m_countField = field::legacyPointCount;
        m_header.pointCount = legacy;
        if (m_header.versionMinor >= 4) {
            const std::uint64_t full = loadRaw<std::uint64_t>(&m_bytes[field::pointCount]);
            if (full != 0 && legacy != 0 && full != legacy) {
                fail(InputErrorKind::CountMismatch, field::pointCount,
                     "the 64-bit point count " + std::to_string(full) +
                         " disagrees with the legacy point count " + std::to_string(legacy) +
                         " at byte " + std::to_string(field::legacyPointCount) +
                         ", expected equal counts (or a legacy count of 0)");
            }
            if (full != 0 || legacy == 0) {
                m_countField = field::pointCount;
                m_header.pointCount = full;
            }
        }
        if (m_header.pointCount == 0) {
            fail(InputErrorKind::NoPoints, m_countField,
                 "the header declares 0 point records, expected at least one point");
        }
    }

    // Bytes after the last record are allowed (LAS 1.4 EVLRs follow the points).
    void checkFileHoldsEveryRecord() {
        if (m_header.compressed) {
            return; // chunks of any size: the LAZ reader checks them
        }
        const std::uint64_t fileSize = m_stream.size();
        const std::uint64_t available =
            (fileSize - m_header.pointDataOffset) / m_header.recordLength;
        if (available >= m_header.pointCount) {
            return;
        }
        const std::uint64_t firstMissing = available;
        fail(InputErrorKind::Truncated, m_header.recordOffset(firstMissing),
             "point record " + std::to_string(firstMissing) + " (counting from 0) of " +
                 std::to_string(m_header.pointCount) + " declared at byte " +
                 std::to_string(m_countField) + " needs " + std::to_string(m_header.recordLength) +
                 " bytes here, but the file ends at byte " + std::to_string(fileSize) +
                 " (it holds " + std::to_string(available) + " whole records)");
    }

    void readDeclaredBounds() {
        const auto at = [&](int index) {
            return loadRaw<double>(&m_bytes[field::bounds + 8 * index]);
        };
        m_header.declaredBounds.max = {at(0), at(2), at(4)};
        m_header.declaredBounds.min = {at(1), at(3), at(5)};
    }

    FileStream& m_stream;
    std::array<std::uint8_t, kHeaderSize14> m_bytes{};
    std::size_t m_available = 0;
    std::size_t m_countField = field::legacyPointCount;
    Header m_header;
};

} // namespace

std::uint16_t requiredHeaderSize(std::uint8_t versionMinor) {
    if (versionMinor >= 4) {
        return kHeaderSize14;
    }
    return versionMinor == 3 ? kHeaderSize13 : kHeaderSize12;
}

std::string fixedLengthText(const std::uint8_t* bytes, std::size_t capacity) {
    const auto* begin = reinterpret_cast<const char*>(bytes);
    return std::string(begin, std::find(begin, begin + capacity, '\0'));
}

std::uint16_t minimumRecordLength(std::uint8_t pointFormat) {
    return kMinimumRecordLengths.at(pointFormat);
}

bool formatHasColor(std::uint8_t pointFormat) {
    return pointFormat <= kMaxPointFormat && kColorOffsets[pointFormat] != 0;
}

std::size_t colorOffset(std::uint8_t pointFormat) {
    return kColorOffsets.at(pointFormat);
}

bool Header::hasUsableBounds() const {
    const auto finite = [](const glm::dvec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    return finite(declaredBounds.min) && finite(declaredBounds.max) && !declaredBounds.empty();
}

Header readHeader(FileStream& stream) {
    return HeaderParser(stream).parse();
}

} // namespace omicron::las
