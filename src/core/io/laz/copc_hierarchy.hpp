// COPC (cloud-optimised point cloud, a LAZ 1.4 file whose chunks are the nodes of an octree):
// the 'copc' info record and the hierarchy pages, which say which chunk holds which node. The
// LAZ reader uses them for a preview: the top levels of COPC's own level of detail are a
// uniform sample of the whole cloud, available before the first sorted batch.
#pragma once

#include "io/file_stream.hpp"
#include "io/las/las_header.hpp"

#include <cstdint>
#include <optional>
#include <vector>

namespace omicron::laz {

// The 'copc' info record (user id "copc", record id 1, 160 bytes), the first VLR of the file.
struct CopcInfo {
    double center[3] = {0.0, 0.0, 0.0};
    double halfSize = 0.0;
    double spacing = 0.0;
    std::uint64_t rootPageOffset = 0; // the root hierarchy page, in the file
    std::uint64_t rootPageBytes = 0;
};

// A data node of the hierarchy: its key and its chunk.
struct CopcNode {
    std::int32_t level = 0, x = 0, y = 0, z = 0;
    std::uint64_t offset = 0; // of the node's LAZ chunk
    std::uint32_t bytes = 0;
    std::uint32_t pointCount = 0;
};

// The info record when `header`'s file is COPC (its first VLR is 'copc' id 1), nullopt
// otherwise. Throws InputError naming the byte when the record or its root page lies outside
// the file or has an impossible size.
std::optional<CopcInfo> readCopcInfo(FileStream& stream, const las::Header& header);

// The nodes of the root page's first levels, level by level, as many whole levels as hold
// at most `maxPoints` points together (level 0 always). Throws InputError naming the byte of
// a page that is truncated or not a whole number of 32-byte entries.
std::vector<CopcNode> readCopcTopNodes(FileStream& stream, const CopcInfo& info,
                                       std::uint64_t maxPoints);

} // namespace omicron::laz
