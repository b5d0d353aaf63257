// The .omh hierarchy file: a finished OMiCroN hierarchy, stored so that it reloads top-down,
// level by level (the paper's pipeline 3): a viewer draws the root while deeper levels load.
//
// Layout (all little-endian, 64-bit offsets and counts; docs/FORMATS.md has the byte tables):
//   header       256 bytes  magic "OMICRONH", version, endianness marker, totals, build
//                           parameters (depth, ratio, collapse), attribute layout, cube and
//                           source offset; XXH64 of the 248 bytes before it
//   level table  L x 64 + 8 per level: nodes, leaves, points, node-table and payload offsets,
//                           XXH3-64 of the level's node records and of its payload, the
//                           points of its sparse nodes; then XXH64 of the entries
//   (version 4)  the deepest level's payload: each field of its records as a column of its
//                           own (positions, normals, colours, intensities, LAS column; each
//                           from a 4096-byte boundary), then its sparse nodes' splat attributes
//   node table   32 bytes per node, breadth first: level 0, then level 1 ... each level in
//                           Morton order (code, first point, point count, splat scale, child
//                           mask, flags)
//   payload      per level: R bytes per held point, grouped by node in node-table order;
//                           then the splat attributes of the points of its sparse nodes
//                           (version 4: every level but the deepest)
//   footer       32 bytes   magic "OMHEND\0\0", total nodes, total points, XXH64 of them
//
// Each level has its own checksums so a progressive reader verifies a level before it
// publishes it; nothing from a damaged section ever reaches a renderer.
#pragma once

#include "build/build_options.hpp"
#include "build/splat_estimator.hpp"
#include "formats/oms_format.hpp"
#include "points/cube_transform.hpp"
#include "points/point_batch.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

namespace omicron::omh {

inline constexpr std::array<char, 8> kMagic{'O', 'M', 'I', 'C', 'R', 'O', 'N', 'H'};
inline constexpr std::array<char, 8> kFooterMagic{'O', 'M', 'H', 'E', 'N', 'D', '\0', '\0'};
// Version 2 added uniform columns (header bytes 130-247, zero in version 1, which still loads).
// Version 3 took the splat attributes out of the records: a reader estimates them from the
// node's points as a build does (the same bytes), except for the points of sparse nodes
// (fewer than kMinPointsPerSplatEstimate points, whose estimate borrows points of other nodes),
// stored after their level's records; the level entry gained their count (56 -> 64 bytes).
// Version 4 stores the deepest level (most of the points) as columns, right after the level
// table, where its place depends only on the depth: they are the sorted cloud's arrays
// verbatim, so `build --save` writes them from the cloud's memory while the hierarchy is still
// being built (omh_column_stream.hpp), with direct I/O, neither encoding nor copying them.
inline constexpr std::uint32_t kVersion = 4;
inline constexpr std::uint32_t kOldestVersion = 1;
inline constexpr std::uint32_t kFirstVersionWithoutSplatRecords = 3;
inline constexpr std::uint32_t kFirstVersionWithDeepestColumns = 4;
// Each column of the deepest level starts on a multiple of this (direct I/O's alignment).
inline constexpr std::uint64_t kColumnAlignment = 4096;
inline constexpr std::uint32_t kEndiannessMarker = oms::kEndiannessMarker;
inline constexpr std::uint8_t kKnownAttributeBits = oms::kKnownAttributeBits;
// Splat bit 0: a point's splat attributes include the estimated normal (the cloud has no
// normals of its own).
inline constexpr std::uint8_t kSplatEstimatedNormal = 0x01;
inline constexpr std::uint8_t kKnownNodeFlags = 0x03; // NodeFlag::Leaf | NodeFlag::Collapsed

inline constexpr std::size_t kHeaderBytes = 256;
inline constexpr std::size_t kLevelEntryBytesBeforeV3 = 56;
inline constexpr std::size_t kLevelEntryBytes = 64;
constexpr std::size_t levelEntryBytes(std::uint32_t version) {
    return version >= kFirstVersionWithoutSplatRecords ? kLevelEntryBytes
                                                       : kLevelEntryBytesBeforeV3;
}
inline constexpr std::size_t kNodeRecordBytes = 32;
inline constexpr std::size_t kFooterBytes = 32;

namespace header {
inline constexpr std::size_t kMagic = 0;            // char[8]
inline constexpr std::size_t kVersion = 8;          // u32
inline constexpr std::size_t kEndianness = 12;      // u32
inline constexpr std::size_t kTotalNodes = 16;      // u64
inline constexpr std::size_t kTotalPoints = 24;     // u64, payload records
inline constexpr std::size_t kInputPoints = 32;     // u64, points of the source cloud
inline constexpr std::size_t kDroppedPoints = 40;   // u64, LeafCollapse::Paper
inline constexpr std::size_t kCollapsedLeaves = 48; // u64
inline constexpr std::size_t kMaxLevel = 56;        // u8, 1..21
inline constexpr std::size_t kLevelCount = 57;      // u8, max level + 1
inline constexpr std::size_t kCollapse = 58;        // u8, 0 off, 1 lossless, 2 paper
inline constexpr std::size_t kAttributes = 59;      // u8, AttributeSet::bits()
inline constexpr std::size_t kSplatBits = 60;       // u8
inline constexpr std::size_t kReserved0 = 61;       // u8, zero
inline constexpr std::size_t kRecordBytes = 62;     // u16
inline constexpr std::size_t kRatio = 64;           // f64, (0, 1]
inline constexpr std::size_t kCubeOrigin = 72;      // f64[3]
inline constexpr std::size_t kCubeEdge = 96;        // f64, > 0
inline constexpr std::size_t kSourceOffset = 104;   // f64[3]
inline constexpr std::size_t kExtraBytes = 128;     // u16, LAS extra bytes a point (Las only)
// Version 2: a column every point holds the same value of is stored here once, not in the
// records (a uniform column: see SortedCloud::setUniformColumns). Version 1: all zero.
inline constexpr std::size_t kUniformColumns = 130;   // u8, kUniform* bits
inline constexpr std::size_t kReserved2 = 131;        // u8, zero
inline constexpr std::size_t kUniformIntensity = 132; // u16, with kUniformIntensityBit, else 0
inline constexpr std::size_t kUniformLasRecord = 134; // the LAS column's record, with
                                                      // kUniformLasBit; zero to kChecksum
inline constexpr std::size_t kChecksum = 248;         // u64, XXH64 of bytes [0, 248)
} // namespace header

inline constexpr std::uint8_t kUniformIntensityBit = 0x01;
inline constexpr std::uint8_t kUniformLasBit = 0x02;
// A longer LAS record (many extra bytes) stays in the records even when it is uniform.
inline constexpr std::size_t kMaxUniformLasBytes = header::kChecksum - header::kUniformLasRecord;

namespace level {
inline constexpr std::size_t kNodes = 0;             // u64
inline constexpr std::size_t kLeaves = 8;            // u64
inline constexpr std::size_t kPoints = 16;           // u64, records held by the level's nodes
inline constexpr std::size_t kNodeTableOffset = 24;  // u64, absolute byte offset
inline constexpr std::size_t kPayloadOffset = 32;    // u64, absolute byte offset
inline constexpr std::size_t kNodeChecksum = 40;     // u64, XXH3-64 of the level's node records
inline constexpr std::size_t kPayloadChecksum = 48;  // u64, XXH3-64 of the level's payload
inline constexpr std::size_t kSparsePoints = 56;     // u64, version 3: points of sparse nodes
} // namespace level

namespace node {
inline constexpr std::size_t kCode = 0;        // u64, Morton code with sentinel bit
inline constexpr std::size_t kFirstPoint = 8;  // u64, first record, counted from the payload start
inline constexpr std::size_t kPointCount = 16; // u64, >= 1
inline constexpr std::size_t kSplatScale = 24; // f32, finite, > 0
inline constexpr std::size_t kChildMask = 28;  // u8, bit o: the child with octant o exists
inline constexpr std::size_t kFlags = 29;      // u8, NodeFlag bits
inline constexpr std::size_t kReserved = 30;   // u16, zero
} // namespace node

namespace footer {
inline constexpr std::size_t kMagic = 0;       // char[8]
inline constexpr std::size_t kTotalNodes = 8;  // u64
inline constexpr std::size_t kTotalPoints = 16; // u64
inline constexpr std::size_t kChecksum = 24;   // u64, XXH64 of footer bytes [0, 24)
} // namespace footer

// The attributes a record carries: the cloud's but its uniform columns (kUniform* bits).
constexpr AttributeSet recordAttributes(AttributeSet attributes, std::uint8_t uniformColumns) {
    std::uint8_t bits = attributes.bits();
    std::uint16_t extraBytes = attributes.extraBytes();
    if ((uniformColumns & kUniformIntensityBit) != 0) {
        bits &= static_cast<std::uint8_t>(~static_cast<unsigned>(Attribute::Intensity));
    }
    if ((uniformColumns & kUniformLasBit) != 0) {
        bits &= static_cast<std::uint8_t>(~static_cast<unsigned>(Attribute::Las) &
                                          ~static_cast<unsigned>(Attribute::GpsTime) &
                                          ~static_cast<unsigned>(Attribute::Nir));
        extraBytes = 0;
    }
    return AttributeSet::fromBits(bits, extraBytes);
}

// A point's splat attributes: the radius (encodeRadius) and, when the splat bit says so, the
// octahedral estimated normal.
constexpr std::size_t splatBytes(bool estimatedNormal) {
    return sizeof(std::uint16_t) + (estimatedNormal ? sizeof(std::uint32_t) : 0);
}

// A point record: the .oms record (position, optional normal, colour, intensity, LAS column;
// not the uniform columns), then before version 3 the point's splat attributes.
struct RecordLayout {
    oms::RecordLayout point;
    AttributeSet attributes; // what the record carries of the cloud's attributes
    bool splats = false;     // the record ends with the splat attributes (before version 3)
    bool estimatedNormal = false; // a point's splat attributes include the estimated normal
    std::size_t radiusOffset = 0;
    std::size_t estimatedNormalOffset = 0; // 0: none in the record
    std::size_t bytes = 0;

    static constexpr RecordLayout of(AttributeSet attributes, bool estimatedNormal,
                                     std::uint8_t uniformColumns, std::uint32_t version) {
        RecordLayout layout;
        layout.attributes = recordAttributes(attributes, uniformColumns);
        layout.point = oms::RecordLayout::of(layout.attributes);
        layout.bytes = layout.point.bytes;
        layout.estimatedNormal = estimatedNormal;
        layout.splats = version < kFirstVersionWithoutSplatRecords;
        if (layout.splats) {
            layout.radiusOffset = layout.point.bytes;
            if (estimatedNormal) {
                layout.estimatedNormalOffset = layout.radiusOffset + sizeof(std::uint16_t);
            }
            layout.bytes += splatBytes(estimatedNormal);
        }
        return layout;
    }
};

// A field of a point record, stored as a column of its own in a columnar level (version 4's
// deepest), in this order.
enum class ColumnKind { Position, Normal, Color, Intensity, Las };
struct Column {
    ColumnKind kind;
    std::size_t bytes; // per point
};
// The columns of records of `layout`: its fields, in record order.
std::vector<Column> recordColumns(const RecordLayout& layout);
const char* columnName(ColumnKind kind); // "position", "normal", ...

constexpr std::uint64_t alignUp(std::uint64_t offset, std::uint64_t alignment) {
    return (offset + alignment - 1) / alignment * alignment;
}
// Where a column of a columnar level lies, relative to the level's first byte (aligned):
// its values in [begin, end), then zeros up to paddingEnd, where the next column starts (after
// the last column: the level's sparse splat attributes, from a boundary of their own).
struct ColumnSpan {
    std::uint64_t begin;
    std::uint64_t end;
    std::uint64_t paddingEnd;
};
std::vector<ColumnSpan> columnSpans(const std::vector<Column>& columns, std::uint64_t points);
// The checksum of a columnar level's payload: XXH3-64 of the XXH3-64 digests of its columns
// then of its sparse splat attributes, each as 8 little-endian bytes (the columns are hashed
// separately, as they are written: side by side while the build publishes points).
std::uint64_t columnarChecksum(const std::vector<std::uint64_t>& digests);

// A node whose splat attributes a version 3 file stores (after its level's records): one too
// sparse for an estimate from its own points. kMinPointsPerSplatEstimate's value is part of
// the format.
constexpr bool storesSplats(std::uint64_t nodePoints) {
    return nodePoints < kMinPointsPerSplatEstimate;
}
// Whether a file of `layout` stores a node's splat attributes: every node's in its records
// before version 3, a sparse node's after its level's records from version 3 on.
constexpr bool storesSplats(const RecordLayout& layout, std::uint64_t nodePoints) {
    return layout.splats || storesSplats(nodePoints);
}

// What determines the stored hierarchy besides its input, and the build's counts worth keeping.
struct BuildInfo {
    int maxLevel = 7;
    double ratio = 0.2;
    LeafCollapse collapse = LeafCollapse::Off;
    std::uint64_t inputPoints = 0;
    std::uint64_t droppedPoints = 0;
    std::uint64_t collapsedLeaves = 0;
};

struct LevelEntry {
    std::uint64_t nodes = 0;
    std::uint64_t leaves = 0;
    std::uint64_t points = 0;
    std::uint64_t nodeTableOffset = 0;
    std::uint64_t payloadOffset = 0;
    std::uint64_t nodeChecksum = 0;
    std::uint64_t payloadChecksum = 0;
    std::uint64_t sparsePoints = 0; // version 3: points of the nodes that storesSplats()
    bool columnar = false; // version 4's deepest level: stored as columns (Header::setLevels)
};

// Everything the header and level table say.
struct Header {
    std::string path;
    std::uint32_t version = kVersion;
    std::uint64_t fileBytes = 0;
    BuildInfo build;
    AttributeSet attributes;
    bool estimatedNormals = false;
    // Version 2: the uniform columns (kUniform* bits) and their values.
    std::uint8_t uniformColumns = 0;
    std::uint16_t uniformIntensity = 0;
    std::vector<std::uint8_t> uniformLasRecord; // attributes.lasBytes() bytes, or none
    std::size_t recordBytes = 0;
    CubeTransform cube;
    glm::dvec3 sourceOffset{0.0};
    std::uint64_t totalNodes = 0;
    std::uint64_t totalPoints = 0;
    std::vector<LevelEntry> levels; // index = level, 0..maxLevel

    bool splatsInRecords() const { return version < kFirstVersionWithoutSplatRecords; }
    // Bytes of one point's stored splat attributes (in its record, or after its level's).
    std::size_t splatBytes() const { return omh::splatBytes(estimatedNormals); }
    // Version 4: the deepest level is stored as columns.
    bool columnar(const LevelEntry& level) const { return level.columnar; }
    // Sizes the level table for `count` levels, marking the columnar one (set the version
    // first).
    void setLevelCount(std::size_t count) {
        levels.assign(count, LevelEntry{});
        if (version >= kFirstVersionWithDeepestColumns && count > 0) {
            levels.back().columnar = true;
        }
    }
    // The record layout's fields, as a columnar level stores them.
    std::vector<Column> columns() const;
    // A level's records: R bytes each, or (columnar) its columns with their alignment, up to
    // the next multiple of kColumnAlignment.
    std::uint64_t recordsBytes(const LevelEntry& level) const;
    // A level's payload: its records, then (version 3) its sparse nodes' splat attributes.
    std::uint64_t payloadBytes(const LevelEntry& level) const {
        return recordsBytes(level) + level.sparsePoints * splatBytes();
    }
    // Where the splat attributes of a level's sparse nodes start.
    std::uint64_t sparseSplatsOffset(const LevelEntry& level) const {
        return level.payloadOffset + recordsBytes(level);
    }
    std::uint64_t levelTableOffset() const { return kHeaderBytes; }
    std::uint64_t levelTableEnd() const {
        return kHeaderBytes + levels.size() * levelEntryBytes(version) + 8;
    }
    // Version 4: where the deepest level's columns start (right after the level table).
    std::uint64_t columnsOffset() const { return alignUp(levelTableEnd(), kColumnAlignment); }
    std::uint64_t nodeTableOffset() const {
        if (version < kFirstVersionWithDeepestColumns || levels.empty()) {
            return levelTableEnd();
        }
        return columnsOffset() + payloadBytes(levels.back());
    }
    // Where the payloads after the node table start (level 0's).
    std::uint64_t payloadOffset() const { return nodeTableOffset() + totalNodes * kNodeRecordBytes; }
    std::uint64_t footerOffset() const {
        std::uint64_t end = payloadOffset();
        for (const LevelEntry& level : levels) {
            end += columnar(level) ? 0 : payloadBytes(level);
        }
        return end;
    }
};

// Sets every level's node-table and payload offsets to where the version's layout puts them,
// from the counts: the writer's plan, and what a reader expects.
void assignOffsets(Header& header);

std::uint8_t encodeCollapse(LeafCollapse collapse);

// XXH64 (seed 0) of small fixed sections (header, level table, footer).
std::uint64_t smallChecksum(const void* bytes, std::size_t count);

std::array<std::uint8_t, kHeaderBytes> encodeHeader(const Header& header);
// The level entries and their checksum, levels.size() * levelEntryBytes(version) + 8 bytes.
std::vector<std::uint8_t> encodeLevelTable(const std::vector<LevelEntry>& levels,
                                           std::uint32_t version);
std::array<std::uint8_t, kFooterBytes> encodeFooter(std::uint64_t totalNodes,
                                                    std::uint64_t totalPoints);

} // namespace omicron::omh
