// The point records of a LAZ file (COPC included: its points are LAZ 1.4 chunks), decoded
// chunk by chunk behind the LAS reader's record-source interface.
//
// Streaming with bounded memory: a batch of consecutive chunks (about 64 MiB of compressed
// and decoded bytes) is read in one go, its chunks decoded in parallel by oneTBB, then
// delivered in file order on the calling thread; then the next batch. A chunk too large for a
// batch is decoded alone, in slices. Decoded records do not depend on the thread count.
#pragma once

#include "io/file_stream.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_record_source.hpp"

#include <cstdint>
#include <memory>

namespace omicron {

// How much a LAZ read holds at once.
struct LazStreaming {
    // Compressed plus decoded bytes of the chunks decoded together. Chunks of the default
    // 50,000 points make 1 to 4 MB each, so a batch holds enough of them for every thread.
    std::uint64_t batchBytes = std::uint64_t{64} << 20;
    // A chunk whose records alone exceed batchBytes is decoded alone, this many bytes of
    // records at a time.
    std::uint64_t sliceBytes = std::uint64_t{8} << 20;
};

// `header` was read from `stream` and is compressed. Parses the 'laszip encoded' record and
// the chunk table; throws InputError (see laz/laszip_vlr.hpp and laz/chunk_table.hpp). The
// source's blocks and samples throw InputError (CorruptData) naming the file, the chunk and
// the byte for a chunk that does not decode.
std::unique_ptr<LasRecordSource> openLazRecords(std::unique_ptr<FileStream> stream,
                                                const las::Header& header,
                                                const LazStreaming& streaming = {});

} // namespace omicron
