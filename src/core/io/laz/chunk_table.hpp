// Where a LAZ file's chunks are. A chunked file starts its point data with the 64-bit offset
// of the chunk table (or -1: then the file's last 8 bytes hold it); the table holds a version
// (0), the number of chunks, and, arithmetic-coded, each chunk's byte size (and point count,
// for variable chunks) as differences from the chunk before. The table is what lets chunks be
// decoded independently, in parallel.
#pragma once

#include "io/file_stream.hpp"
#include "io/laz/laszip_vlr.hpp"

#include <cstdint>
#include <vector>

namespace omicron::laz {

struct Chunk {
    std::uint64_t firstPoint = 0; // index of the chunk's first point in the file
    std::uint64_t pointCount = 0;
    std::uint64_t offset = 0; // byte of the file where the chunk starts
    std::uint64_t bytes = 0;
};

struct ChunkLayout {
    std::vector<Chunk> chunks;     // in file order, contiguous
    std::uint64_t tableOffset = 0; // 0 without a table (one point-wise chunk)
};

// What the chunk table is checked against.
struct PointDataExtent {
    std::uint64_t offset = 0;     // the header's offset to the point data
    std::uint64_t end = 0;        // where the point data must end: EVLRs or the file's end
    std::uint64_t pointCount = 0; // the header's
    std::uint16_t recordLength = 0;
};

// Reads and checks the chunks of a file compressed as `vlr` says. Every chunk is non-empty,
// holds at least one point, lies inside the point data and follows the one before; their
// points add up to the header's count. Allocates at most one entry per record's worth of
// point data bytes. Throws InputError naming the byte: Truncated (the table lies beyond the
// file's end), CorruptData (a table that does not decode or describes impossible chunks),
// CountMismatch (the chunks hold another number of points than the header declares).
ChunkLayout readChunkLayout(FileStream& stream, const LaszipVlr& vlr, const PointDataExtent& data);

} // namespace omicron::laz
