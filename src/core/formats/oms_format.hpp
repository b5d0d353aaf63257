// The .oms sorted stream: a cloud in Morton order, written once, streamed straight from disk
// into a SortedCloud (the paper's pipeline 2), so a second session skips reading and sorting.
//
// Layout (all little-endian; docs/FORMATS.md has the byte-by-byte table):
//   header   128 bytes   magic "OMICRONS", version, endianness marker, point count, sort
//                        depth, attribute bits, record size, LAS extra bytes, uniform column
//                        bits, cube (origin, edge), source offset, uniform values, XXH64 of
//                        the 120 bytes before it
//   records  count x R   float x y z (unit cube) [float nx ny nz] [u8 r g b] [u16 intensity]
//                        [LAS column: points/las_fields.hpp], packed, in non-decreasing
//                        Morton order; a uniform column is in the header, not the records
//   footer   24 bytes    magic "OMSEND\0\0", point count again, XXH3-64 of all record bytes
//
// The Morton code is not stored: morton::encodeUnit on the stored float position gives the
// same code bit for bit on every machine, and leaving it out saves 8 of ~20-37 bytes per point.
// The header has its own checksum so a damaged header is rejected at open, before a
// SortedCloud of the declared size is allocated; the payload checksum can only be checked once
// the stream has been read, which the reader does before declaring the cloud complete.
#pragma once

#include "points/point_batch.hpp"
#include "points/point_records.hpp"

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace omicron {
class SortedCloud;
}

namespace omicron::oms {

// Records are memcpy'd from and to the host's floats; the endianness marker lets a reader on
// such a host tell a foreign file apart instead of decoding garbage.
static_assert(std::endian::native == std::endian::little, "the .oms code assumes little-endian");

inline constexpr std::array<char, 8> kMagic{'O', 'M', 'I', 'C', 'R', 'O', 'N', 'S'};
inline constexpr std::array<char, 8> kFooterMagic{'O', 'M', 'S', 'E', 'N', 'D', '\0', '\0'};
// Version 2 added the uniform columns; version 1 files (all of those fields zero) still load.
inline constexpr std::uint32_t kVersion = 2;
inline constexpr std::uint32_t kOldestVersion = 1;
// Written as a native u32: bytes 04 03 02 01 on disk; a big-endian writer would put 01 02 03 04.
inline constexpr std::uint32_t kEndiannessMarker = 0x01020304u;
inline constexpr std::uint8_t kSortDepth = 21; // morton::kMaxLevel, the level codes are sorted at
// Normal | Color | Intensity | Las | GpsTime | Nir
inline constexpr std::uint8_t kKnownAttributeBits = 0x3f;

inline constexpr std::size_t kHeaderBytes = 128;
inline constexpr std::size_t kFooterBytes = 24;

// Byte offsets of the header fields.
namespace header {
inline constexpr std::size_t kMagic = 0;         // char[8]
inline constexpr std::size_t kVersion = 8;       // u32
inline constexpr std::size_t kEndianness = 12;   // u32
inline constexpr std::size_t kPointCount = 16;   // u64
inline constexpr std::size_t kSortDepth = 24;    // u8
inline constexpr std::size_t kAttributes = 25;   // u8, AttributeSet::bits()
inline constexpr std::size_t kRecordBytes = 26;  // u16
inline constexpr std::size_t kExtraBytes = 28;   // u16, LAS extra bytes a point (Las only)
// Version 2: a column every point holds the same value of is stored once here, not in the
// records (as in a .omh). Version 1: all zero.
inline constexpr std::size_t kUniformColumns = 30;   // u8, kUniform* bits
inline constexpr std::size_t kReserved0 = 31;        // u8, zero
inline constexpr std::size_t kCubeOrigin = 32;       // f64[3], source units
inline constexpr std::size_t kCubeEdge = 56;         // f64, > 0
inline constexpr std::size_t kSourceOffset = 64;     // f64[3]
inline constexpr std::size_t kUniformIntensity = 88; // u16, with kUniformIntensityBit, else 0
inline constexpr std::size_t kUniformLasRecord = 90; // the LAS column's record, with
                                                     // kUniformLasBit; zero to kChecksum
inline constexpr std::size_t kChecksum = 120;        // u64, XXH64 (seed 0) of bytes [0, 120)
} // namespace header

inline constexpr std::uint8_t kUniformIntensityBit = 0x01;
inline constexpr std::uint8_t kUniformLasBit = 0x02;
// A longer LAS record (many extra bytes) stays in the records even when it is uniform.
inline constexpr std::size_t kMaxUniformLasBytes = header::kChecksum - header::kUniformLasRecord;

// Byte offsets of the footer fields, relative to the footer's start.
namespace footer {
inline constexpr std::size_t kMagic = 0;      // char[8]
inline constexpr std::size_t kPointCount = 8; // u64, equal to the header's
inline constexpr std::size_t kChecksum = 16;  // u64, XXH3-64 (seed 0) of every record byte
} // namespace footer

// The record layout (points/point_records.hpp), shared with the sorter's scratch runs.
using RecordLayout = PointRecordLayout;

// The columns every point of a file shares one value of, stored once in the header.
struct UniformColumns {
    std::uint8_t bits = 0;               // kUniform* bits
    std::uint16_t intensity = 0;         // with kUniformIntensityBit
    std::vector<std::uint8_t> lasRecord; // with kUniformLasBit: the LAS column's bytes

    bool intensityUniform() const { return (bits & kUniformIntensityBit) != 0; }
    bool lasUniform() const { return (bits & kUniformLasBit) != 0; }
};

// The uniform columns of `cloud` a header can hold (a LAS record of at most
// kMaxUniformLasBytes).
UniformColumns uniformColumnsOf(const SortedCloud& cloud);

// A record of `attributes` without the columns `uniform` holds: the layout of a file's records.
RecordLayout storedRecordLayout(AttributeSet attributes, const UniformColumns& uniform);

// XXH64 (seed 0) of a header's first header::kChecksum bytes.
std::uint64_t headerChecksum(const std::uint8_t* headerBytes);

// XXH3-64 (seed 0) computed incrementally over the record bytes, in file order.
class PayloadChecksum {
public:
    PayloadChecksum();
    ~PayloadChecksum();
    PayloadChecksum(const PayloadChecksum&) = delete;
    PayloadChecksum& operator=(const PayloadChecksum&) = delete;

    void update(const void* bytes, std::size_t count);
    std::uint64_t digest() const;

private:
    struct State;
    std::unique_ptr<State> m_state;
};

} // namespace omicron::oms
