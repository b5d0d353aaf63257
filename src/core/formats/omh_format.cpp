#include "formats/omh_format.hpp"

#include <cstring>

// Header-only xxHash (Debian's libxxhash-dev), as in oms_format.cpp: no library to link.
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace omicron::omh {

namespace {
template <typename T> void store(std::uint8_t* at, const T& value) {
    std::memcpy(at, &value, sizeof(T));
}
} // namespace

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

std::uint64_t smallChecksum(const void* bytes, std::size_t count) {
    return XXH64(bytes, count, 0);
}

std::array<std::uint8_t, kHeaderBytes> encodeHeader(const Header& h) {
    namespace f = header;
    std::array<std::uint8_t, kHeaderBytes> bytes{}; // reserved fields stay zero
    std::uint8_t* at = bytes.data();
    std::memcpy(at + f::kMagic, kMagic.data(), kMagic.size());
    store(at + f::kVersion, kVersion);
    store(at + f::kEndianness, kEndiannessMarker);
    store(at + f::kTotalNodes, h.totalNodes);
    store(at + f::kTotalPoints, h.totalPoints);
    store(at + f::kInputPoints, h.build.inputPoints);
    store(at + f::kDroppedPoints, h.build.droppedPoints);
    store(at + f::kCollapsedLeaves, h.build.collapsedLeaves);
    store(at + f::kMaxLevel, static_cast<std::uint8_t>(h.build.maxLevel));
    store(at + f::kLevelCount, static_cast<std::uint8_t>(h.levels.size()));
    store(at + f::kCollapse, encodeCollapse(h.build.collapse));
    store(at + f::kAttributes, h.attributes.bits());
    store(at + f::kExtraBytes, h.attributes.extraBytes());
    store(at + f::kSplatBits, h.estimatedNormals ? kSplatEstimatedNormal : std::uint8_t{0});
    store(at + f::kRecordBytes, static_cast<std::uint16_t>(h.recordBytes));
    store(at + f::kRatio, h.build.ratio);
    for (int axis = 0; axis < 3; ++axis) {
        store(at + f::kCubeOrigin + 8 * axis, h.cube.origin[axis]);
        store(at + f::kSourceOffset + 8 * axis, h.sourceOffset[axis]);
    }
    store(at + f::kCubeEdge, h.cube.edge);
    store(at + f::kChecksum, smallChecksum(at, f::kChecksum));
    return bytes;
}

std::vector<std::uint8_t> encodeLevelTable(const std::vector<LevelEntry>& levels) {
    std::vector<std::uint8_t> bytes(levels.size() * kLevelEntryBytes + 8);
    for (std::size_t l = 0; l < levels.size(); ++l) {
        std::uint8_t* at = bytes.data() + l * kLevelEntryBytes;
        const LevelEntry& e = levels[l];
        store(at + level::kNodes, e.nodes);
        store(at + level::kLeaves, e.leaves);
        store(at + level::kPoints, e.points);
        store(at + level::kNodeTableOffset, e.nodeTableOffset);
        store(at + level::kPayloadOffset, e.payloadOffset);
        store(at + level::kNodeChecksum, e.nodeChecksum);
        store(at + level::kPayloadChecksum, e.payloadChecksum);
    }
    const std::size_t entryBytes = levels.size() * kLevelEntryBytes;
    store(bytes.data() + entryBytes, smallChecksum(bytes.data(), entryBytes));
    return bytes;
}

std::array<std::uint8_t, kFooterBytes> encodeFooter(std::uint64_t totalNodes,
                                                    std::uint64_t totalPoints) {
    std::array<std::uint8_t, kFooterBytes> bytes{};
    std::memcpy(bytes.data() + footer::kMagic, kFooterMagic.data(), kFooterMagic.size());
    store(bytes.data() + footer::kTotalNodes, totalNodes);
    store(bytes.data() + footer::kTotalPoints, totalPoints);
    store(bytes.data() + footer::kChecksum, smallChecksum(bytes.data(), footer::kChecksum));
    return bytes;
}

} // namespace omicron::omh
