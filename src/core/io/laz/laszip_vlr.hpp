// The "laszip encoded" variable length record (user id "laszip encoded", record 22204): how a
// LAZ file's points are compressed. Parsed and checked against the LAS header before any
// point is decoded, so that every later decoder may trust it.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace omicron::laz {

enum class Compressor : std::uint16_t {
    None = 0,
    Pointwise = 1,        // LAZ 1.0: one chunk for the whole file, no chunk table
    PointwiseChunked = 2, // formats 0-5
    LayeredChunked = 3,   // formats 6-10 (LAS 1.4)
};

enum class ItemType : std::uint16_t {
    Byte = 0,
    Point10 = 6,
    GpsTime11 = 7,
    Rgb12 = 8,
    WavePacket13 = 9,
    Point14 = 10,
    Rgb14 = 11,
    RgbNir14 = 12,
    WavePacket14 = 13,
    Byte14 = 14,
};

const char* toString(ItemType type);

struct Item {
    ItemType type = ItemType::Byte;
    std::uint16_t size = 0;    // bytes of the record it fills
    std::uint16_t version = 0; // 1 or 2 for the point-wise items, 3 or 4 for the layered ones
};

// Chunks hold this many points each, except the last; or, with variable chunks, each chunk's
// count is in the chunk table.
inline constexpr std::uint32_t kVariableChunkSize = 0xFFFFFFFFu;

struct LaszipVlr {
    Compressor compressor = Compressor::None;
    std::uint16_t coder = 0; // 0: arithmetic, the only one
    std::uint8_t versionMajor = 0, versionMinor = 0;
    std::uint16_t versionRevision = 0;
    std::uint32_t options = 0;
    std::uint32_t chunkSize = 0; // points a chunk, or kVariableChunkSize
    std::vector<Item> items;     // in record order

    bool variableChunks() const { return chunkSize == kVariableChunkSize; }
    std::string describe() const; // e.g. "layered chunks (POINT14 v3, RGBNIR14 v3, BYTE14 v3)"
};

// Parses the record's payload (at byte `payloadOffset` of `path`, for errors) and checks it
// against the header's point format (0-10, compression bits cleared) and record length: a
// known compressor and coder, a chunk size > 0 (where chunks exist), items whose types, versions
// and sizes are those of the point format followed by the extra bytes (at most 1024). Throws
// InputError naming the field's byte: MalformedHeader, or UnsupportedFeature (compressor, coder,
// item type or version, more extra bytes).
LaszipVlr parseLaszipVlr(std::span<const std::uint8_t> payload, const std::string& path,
                         std::uint64_t payloadOffset, std::uint8_t pointFormat,
                         std::uint16_t recordLength);

} // namespace omicron::laz
