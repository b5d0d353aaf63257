// The LAS public header block (versions 1.0 to 1.4) and the point record layouts of point data
// formats 0 to 10: where the fields are, shared by the reader and the writer, and the parse
// that validates a file's header before any point is read. A LAZ file (compressed LAS) has the
// same header; the parse finds its 'laszip encoded' record and leaves the points to io/laz.
#pragma once

#include "io/file_stream.hpp"
#include "points/bounds.hpp"

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

namespace omicron::las {

// Byte offsets of the public header block fields. They are the same in every version; LAS 1.3
// appends the waveform field and LAS 1.4 the EVLR fields and the 64-bit counts.
namespace field {
inline constexpr std::size_t signature = 0;              // "LASF"
inline constexpr std::size_t globalEncoding = 6;         // uint16 (reserved in 1.0)
inline constexpr std::size_t versionMajor = 24;          // uint8
inline constexpr std::size_t versionMinor = 25;          // uint8
inline constexpr std::size_t systemIdentifier = 26;      // char[32]
inline constexpr std::size_t generatingSoftware = 58;    // char[32]
inline constexpr std::size_t headerSize = 94;            // uint16
inline constexpr std::size_t pointDataOffset = 96;       // uint32
inline constexpr std::size_t vlrCount = 100;             // uint32
inline constexpr std::size_t pointFormat = 104;          // uint8; bits 6 and 7 mark LAZ
inline constexpr std::size_t recordLength = 105;         // uint16
inline constexpr std::size_t legacyPointCount = 107;     // uint32
inline constexpr std::size_t legacyPointsByReturn = 111; // uint32[5]
inline constexpr std::size_t scale = 131;                // double[3]
inline constexpr std::size_t offset = 155;               // double[3]
inline constexpr std::size_t bounds = 179;               // double max x, min x, max y, min y, ...
inline constexpr std::size_t pointCount = 247;           // uint64, LAS 1.4
inline constexpr std::size_t pointsByReturn = 255;       // uint64[15], LAS 1.4
} // namespace field

// Header sizes the versions require: 1.0 to 1.2, 1.3 (waveform start), 1.4 (EVLRs, counts).
inline constexpr std::uint16_t kHeaderSize12 = 227;
inline constexpr std::uint16_t kHeaderSize13 = 235;
inline constexpr std::uint16_t kHeaderSize14 = 375;

inline constexpr std::uint8_t kMaxPointFormat = 10;

// A variable length record header: reserved, user id char[16], record id, payload length,
// description char[32].
inline constexpr std::size_t kVlrHeaderSize = 54;
inline constexpr std::uint16_t kLaszipRecordId = 22204; // user id "laszip encoded"
inline constexpr std::uint16_t kExtraBytesRecordId = 4;  // user id "LASF_Spec"

// Offsets inside a point record shared by every format.
inline constexpr std::size_t kRecordIntensity = 12; // after int32 X, Y, Z
inline constexpr std::size_t kRecordReturnBits = 14;

// The header size a version requires (minor 0..4).
std::uint16_t requiredHeaderSize(std::uint8_t versionMinor);

// A text field of `capacity` bytes, up to its first NUL (LAS pads text with NULs and may fill
// the field without one).
std::string fixedLengthText(const std::uint8_t* bytes, std::size_t capacity);

// The standard record length of a point format (0..10): 20, 28, 26, 34, 57, 63, 30, 36, 38,
// 59, 67. A file may declare longer records (extra bytes), never shorter ones.
std::uint16_t minimumRecordLength(std::uint8_t pointFormat);

// Formats 2, 3, 5, 7, 8 and 10 carry uint16 red, green, blue.
bool formatHasColor(std::uint8_t pointFormat);

// Byte offset of the red field inside a record of a format with colour.
std::size_t colorOffset(std::uint8_t pointFormat);

// A validated header: every field the reader relies on has been checked against the file.
struct Header {
    std::uint8_t versionMinor = 0; // the major version is always 1
    std::uint16_t headerSize = 0;
    std::uint32_t pointDataOffset = 0; // VLRs (and LAS 1.0's start signature) lie before it
    std::uint8_t pointFormat = 0;
    std::uint16_t recordLength = 0; // >= minimumRecordLength(pointFormat); extra bytes allowed
    std::uint64_t pointCount = 0;   // > 0, and the file holds every record
    glm::dvec3 scale{1.0};          // finite, non-zero
    glm::dvec3 offset{0.0};         // finite
    Bounds declaredBounds;          // as the header states them; see hasUsableBounds()
    // LAZ: the point format byte has a compression bit (6 or 7) or the file has the 'laszip
    // encoded' record; pointFormat is the format with those bits cleared.
    bool compressed = false;
    std::uint64_t laszipRecordOffset = 0; // byte of the record's payload (compressed only)
    std::uint16_t laszipRecordLength = 0; // payload bytes
    // The 192-byte descriptors of the LASF_Spec Extra Bytes records (id 4), in file order (a
    // writer may split them over several records): names and types of the extra bytes.
    std::vector<std::uint8_t> extraBytesDescriptors;
    // The coordinate system's records (user id "LASF_Projection": GeoTIFF keys, WKT), each as
    // the file stores it (its 54-byte header, then its payload), concatenated.
    std::vector<std::uint8_t> projectionRecords;

    // True when the declared bounds are finite with min <= max on every axis.
    bool hasUsableBounds() const;

    // Byte offset of record `index`.
    std::uint64_t recordOffset(std::uint64_t index) const {
        return pointDataOffset + index * recordLength;
    }
};

// Reads the public header block of `stream` and checks it against the file: signature,
// version (1.0 to 1.4), header size, point format, record length, scale and offset, the
// offset to the point data, the point count and, uncompressed, that the file is long enough
// for every record (trailing bytes, such as LAS 1.4 EVLRs, are allowed; a LAZ file's chunks
// are checked by its reader). Throws InputError naming the field's byte offset:
// MalformedHeader (also: a LAZ compression bit without the 'laszip encoded' record),
// UnsupportedFeature (a newer version), Truncated, CountMismatch (LAS 1.4 legacy and 64-bit
// counts disagree) or NoPoints.
Header readHeader(FileStream& stream);

} // namespace omicron::las
