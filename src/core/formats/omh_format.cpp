#include "formats/omh_format.hpp"

#include "io/raw_bytes.hpp"

#include <cstring>

// Header-only xxHash (Debian's libxxhash-dev), as in oms_format.cpp: no library to link.
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace omicron::omh {

std::uint8_t encodeCollapse(LeafCollapse collapse) {
    switch (collapse) {
    case LeafCollapse::Off:
        return 0;
    case LeafCollapse::Lossless:
        return 1;
    case LeafCollapse::Paper:
        return 2;
    }
    return 0;
}

std::vector<Column> recordColumns(const RecordLayout& layout) {
    const AttributeSet attributes = layout.attributes; // without the uniform columns
    std::vector<Column> columns{{ColumnKind::Position, sizeof(glm::vec3)}};
    if (attributes.has(Attribute::Normal)) {
        columns.push_back({ColumnKind::Normal, sizeof(glm::vec3)});
    }
    if (attributes.has(Attribute::Color)) {
        columns.push_back({ColumnKind::Color, 3});
    }
    if (attributes.has(Attribute::Intensity)) {
        columns.push_back({ColumnKind::Intensity, sizeof(std::uint16_t)});
    }
    if (layout.point.lasBytes != 0) {
        columns.push_back({ColumnKind::Las, layout.point.lasBytes});
    }
    return columns;
}

const char* columnName(ColumnKind kind) {
    switch (kind) {
    case ColumnKind::Position:
        return "position";
    case ColumnKind::Normal:
        return "normal";
    case ColumnKind::Color:
        return "colour";
    case ColumnKind::Intensity:
        return "intensity";
    case ColumnKind::Las:
        return "LAS";
    }
    return "?";
}

std::vector<ColumnSpan> columnSpans(const std::vector<Column>& columns, std::uint64_t points) {
    std::vector<ColumnSpan> spans;
    std::uint64_t begin = 0;
    for (const Column& column : columns) {
        const std::uint64_t end = begin + points * column.bytes;
        // The padding after the last column too: the sparse splat attributes (written after
        // the build, through the page cache) start on a block of their own, so writing them
        // never reads back a block the build wrote with direct I/O (a read that waited 0.17 s
        // behind the write-back of the upper levels).
        spans.push_back({begin, end, alignUp(end, kColumnAlignment)});
        begin = spans.back().paddingEnd;
    }
    return spans;
}

std::uint64_t columnarChecksum(const std::vector<std::uint64_t>& digests) {
    std::vector<std::uint8_t> bytes(digests.size() * 8);
    for (std::size_t i = 0; i < digests.size(); ++i) {
        storeRaw(bytes.data() + 8 * i, digests[i]);
    }
    return XXH3_64bits(bytes.data(), bytes.size());
}

std::vector<Column> Header::columns() const {
    return recordColumns(RecordLayout::of(attributes, estimatedNormals, uniformColumns, version));
}

std::uint64_t Header::recordsBytes(const LevelEntry& level) const {
    if (!columnar(level)) {
        return level.points * recordBytes;
    }
    return columnSpans(columns(), level.points).back().paddingEnd; // a position column always
}

void assignOffsets(Header& header) {
    std::uint64_t nodeOffset = header.nodeTableOffset();
    std::uint64_t payloadOffset = header.payloadOffset();
    for (LevelEntry& entry : header.levels) {
        entry.nodeTableOffset = nodeOffset;
        nodeOffset += entry.nodes * kNodeRecordBytes;
        if (header.columnar(entry)) {
            entry.payloadOffset = header.columnsOffset();
        } else {
            entry.payloadOffset = payloadOffset;
            payloadOffset += header.payloadBytes(entry);
        }
    }
}

std::uint64_t smallChecksum(const void* bytes, std::size_t count) {
    return XXH64(bytes, count, 0);
}

std::array<std::uint8_t, kHeaderBytes> encodeHeader(const Header& h) {
    namespace f = header;
    std::array<std::uint8_t, kHeaderBytes> bytes{}; // reserved fields stay zero
    std::uint8_t* at = bytes.data();
    std::memcpy(at + f::kMagic, kMagic.data(), kMagic.size());
    storeRaw(at + f::kVersion, h.version);
    storeRaw(at + f::kEndianness, kEndiannessMarker);
    storeRaw(at + f::kTotalNodes, h.totalNodes);
    storeRaw(at + f::kTotalPoints, h.totalPoints);
    storeRaw(at + f::kInputPoints, h.build.inputPoints);
    storeRaw(at + f::kDroppedPoints, h.build.droppedPoints);
    storeRaw(at + f::kCollapsedLeaves, h.build.collapsedLeaves);
    storeRaw(at + f::kMaxLevel, static_cast<std::uint8_t>(h.build.maxLevel));
    storeRaw(at + f::kLevelCount, static_cast<std::uint8_t>(h.levels.size()));
    storeRaw(at + f::kCollapse, encodeCollapse(h.build.collapse));
    storeRaw(at + f::kAttributes, h.attributes.bits());
    storeRaw(at + f::kExtraBytes, h.attributes.extraBytes());
    storeRaw(at + f::kSplatBits, h.estimatedNormals ? kSplatEstimatedNormal : std::uint8_t{0});
    storeRaw(at + f::kRecordBytes, static_cast<std::uint16_t>(h.recordBytes));
    storeRaw(at + f::kRatio, h.build.ratio);
    for (int axis = 0; axis < 3; ++axis) {
        storeRaw(at + f::kCubeOrigin + 8 * axis, h.cube.origin[axis]);
        storeRaw(at + f::kSourceOffset + 8 * axis, h.sourceOffset[axis]);
    }
    storeRaw(at + f::kCubeEdge, h.cube.edge);
    storeRaw(at + f::kUniformColumns, h.uniformColumns);
    storeRaw(at + f::kUniformIntensity, h.uniformIntensity);
    if (!h.uniformLasRecord.empty()) { // memcpy from an empty vector's null data is undefined
        std::memcpy(at + f::kUniformLasRecord, h.uniformLasRecord.data(),
                    h.uniformLasRecord.size());
    }
    storeRaw(at + f::kChecksum, smallChecksum(at, f::kChecksum));
    return bytes;
}

std::vector<std::uint8_t> encodeLevelTable(const std::vector<LevelEntry>& levels,
                                           std::uint32_t version) {
    const std::size_t stride = levelEntryBytes(version);
    std::vector<std::uint8_t> bytes(levels.size() * stride + 8);
    for (std::size_t l = 0; l < levels.size(); ++l) {
        std::uint8_t* at = bytes.data() + l * stride;
        const LevelEntry& e = levels[l];
        storeRaw(at + level::kNodes, e.nodes);
        storeRaw(at + level::kLeaves, e.leaves);
        storeRaw(at + level::kPoints, e.points);
        storeRaw(at + level::kNodeTableOffset, e.nodeTableOffset);
        storeRaw(at + level::kPayloadOffset, e.payloadOffset);
        storeRaw(at + level::kNodeChecksum, e.nodeChecksum);
        storeRaw(at + level::kPayloadChecksum, e.payloadChecksum);
        if (stride > level::kSparsePoints) {
            storeRaw(at + level::kSparsePoints, e.sparsePoints);
        }
    }
    const std::size_t entryBytes = levels.size() * stride;
    storeRaw(bytes.data() + entryBytes, smallChecksum(bytes.data(), entryBytes));
    return bytes;
}

std::array<std::uint8_t, kFooterBytes> encodeFooter(std::uint64_t totalNodes,
                                                    std::uint64_t totalPoints) {
    std::array<std::uint8_t, kFooterBytes> bytes{};
    std::memcpy(bytes.data() + footer::kMagic, kFooterMagic.data(), kFooterMagic.size());
    storeRaw(bytes.data() + footer::kTotalNodes, totalNodes);
    storeRaw(bytes.data() + footer::kTotalPoints, totalPoints);
    storeRaw(bytes.data() + footer::kChecksum, smallChecksum(bytes.data(), footer::kChecksum));
    return bytes;
}

} // namespace omicron::omh
