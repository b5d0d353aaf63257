#include "io/laz/copc_hierarchy.hpp"

#include "io/input_error.hpp"
#include "io/raw_bytes.hpp"

#include <algorithm>
#include <cstring>
#include <map>

namespace omicron::laz {

namespace {

constexpr std::size_t kInfoBytes = 160;
constexpr std::size_t kEntryBytes = 32;
// A root page larger than this is not read for a preview (a real one holds a few thousand
// entries): bounds the allocation whatever the file claims.
constexpr std::uint64_t kMaxPageBytes = std::uint64_t{32} << 20;

[[noreturn]] void fail(const FileStream& stream, std::uint64_t at, const std::string& why) {
    throw InputError(InputErrorKind::MalformedHeader, stream.path(), InputLocation::byte(at),
                     "COPC: " + why);
}

} // namespace

std::optional<CopcInfo> readCopcInfo(FileStream& stream, const las::Header& header) {
    const std::uint64_t vlrAt = header.headerSize;
    if (header.versionMinor < 4 || vlrAt + las::kVlrHeaderSize + kInfoBytes > stream.size()) {
        return std::nullopt;
    }
    std::uint8_t vlr[las::kVlrHeaderSize];
    stream.seek(vlrAt);
    stream.readExact(vlr, sizeof vlr, "the first variable length record");
    const bool copc = std::memcmp(vlr + 2, "copc\0", 5) == 0 && loadRaw<std::uint16_t>(vlr + 18) == 1;
    if (!copc) {
        return std::nullopt;
    }
    if (loadRaw<std::uint16_t>(vlr + 20) != kInfoBytes) {
        fail(stream, vlrAt + 20, "the info record holds " +
                                     std::to_string(loadRaw<std::uint16_t>(vlr + 20)) +
                                     " bytes, expected 160");
    }
    std::uint8_t payload[kInfoBytes];
    stream.readExact(payload, sizeof payload, "the COPC info record");
    CopcInfo info;
    for (int axis = 0; axis < 3; ++axis) {
        info.center[axis] = loadRaw<double>(payload + 8 * axis);
    }
    info.halfSize = loadRaw<double>(payload + 24);
    info.spacing = loadRaw<double>(payload + 32);
    info.rootPageOffset = loadRaw<std::uint64_t>(payload + 40);
    info.rootPageBytes = loadRaw<std::uint64_t>(payload + 48);
    const std::uint64_t at = vlrAt + las::kVlrHeaderSize + 40;
    if (info.rootPageBytes == 0 || info.rootPageBytes % kEntryBytes != 0 ||
        info.rootPageBytes > kMaxPageBytes) {
        fail(stream, at + 8, "a root hierarchy page of " + std::to_string(info.rootPageBytes) +
                                 " bytes, expected a non-zero multiple of 32 up to 32 MiB");
    }
    if (info.rootPageOffset > stream.size() ||
        info.rootPageBytes > stream.size() - info.rootPageOffset) {
        fail(stream, at, "the root hierarchy page at byte " + std::to_string(info.rootPageOffset) +
                             " (" + std::to_string(info.rootPageBytes) +
                             " bytes) lies beyond the file's end at " +
                             std::to_string(stream.size()));
    }
    return info;
}

std::vector<CopcNode> readCopcTopNodes(FileStream& stream, const CopcInfo& info,
                                       std::uint64_t maxPoints) {
    std::vector<std::uint8_t> page(static_cast<std::size_t>(info.rootPageBytes));
    stream.seek(info.rootPageOffset);
    stream.readExact(page.data(), page.size(), "the COPC root hierarchy page");
    std::map<std::int32_t, std::vector<CopcNode>> levels;
    for (std::size_t e = 0; e < page.size(); e += kEntryBytes) {
        const std::uint8_t* entry = page.data() + e;
        const auto pointCount = loadRaw<std::int32_t>(entry + 28);
        const auto bytes = loadRaw<std::int32_t>(entry + 24);
        CopcNode node{loadRaw<std::int32_t>(entry),
                      loadRaw<std::int32_t>(entry + 4),
                      loadRaw<std::int32_t>(entry + 8),
                      loadRaw<std::int32_t>(entry + 12),
                      loadRaw<std::uint64_t>(entry + 16),
                      static_cast<std::uint32_t>(std::max(bytes, 0)),
                      static_cast<std::uint32_t>(std::max(pointCount, 0))};
        if (pointCount <= 0 || node.level < 0) {
            continue; // a child page (-1), or a node without points
        }
        if (bytes <= 0 || node.offset > stream.size() || node.bytes > stream.size() - node.offset) {
            fail(stream, info.rootPageOffset + e + 16,
                 "hierarchy entry " + std::to_string(e / kEntryBytes) + " places its chunk at byte " +
                     std::to_string(node.offset) + " (" + std::to_string(bytes) +
                     " bytes), outside the file");
        }
        levels[node.level].push_back(node);
    }
    std::vector<CopcNode> nodes;
    std::uint64_t points = 0;
    for (const auto& [level, members] : levels) {
        std::uint64_t levelPoints = 0;
        for (const CopcNode& node : members) {
            levelPoints += node.pointCount;
        }
        if (!nodes.empty() && points + levelPoints > maxPoints) {
            break;
        }
        nodes.insert(nodes.end(), members.begin(), members.end());
        points += levelPoints;
    }
    return nodes;
}

} // namespace omicron::laz
