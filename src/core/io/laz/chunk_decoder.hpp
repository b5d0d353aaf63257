// Decodes the points of one LAZ chunk into standard LAS point records (the bytes an
// uncompressed LAS file holds), in one call or in slices. Chunks are independent: a decoder
// per chunk, any number of them in parallel.
//
// A point-wise chunk: the first record raw, then every item of every point on one arithmetic
// stream that ends exactly at the chunk's end. A layered chunk: the first record raw, its point
// count (uint32), the byte count of every layer of every item (uint32 each), then the layers.
#pragma once

#include "io/input_error.hpp"
#include "io/laz/chunk_table.hpp"
#include "io/laz/laszip_vlr.hpp"
#include "io/laz/layered_item_decoder.hpp"
#include "io/laz/point14_decoder.hpp"
#include "io/laz/pointwise_item_decoder.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace omicron::laz {

// Which chunk of which file, for error messages.
struct ChunkContext {
    const std::string* path = nullptr;
    std::size_t index = 0;
    std::size_t count = 0; // chunks in the file
    Chunk chunk;
    bool exactEnd = true; // the chunk table says where the chunk ends (not LAZ 1.0)
};

class ChunkDecoder {
public:
    // `vlr` must have been checked against the header (parseLaszipVlr): it outlives the decoder.
    explicit ChunkDecoder(const LaszipVlr& vlr);
    ~ChunkDecoder();
    ChunkDecoder(const ChunkDecoder&) = delete;
    ChunkDecoder& operator=(const ChunkDecoder&) = delete;

    std::size_t recordLength() const { return m_recordLength; }

    // Starts on a chunk whose bytes (context.chunk.bytes of them, at least one record) are
    // `bytes`; they must outlive the decoding. Throws InputError when a layered chunk's layer
    // sizes do not fit the chunk (CorruptData) or its point count is not the one the chunk
    // table and the header give it (CountMismatch).
    void start(std::span<const std::uint8_t> bytes, const ChunkContext& context);

    // Decodes the chunk's next `count` points into `records` (count * recordLength() bytes);
    // count <= remaining(). Throws InputError (CorruptData) naming the chunk and the byte where
    // its data ran out when the data ends before the points it holds (a truncated or corrupt
    // chunk), or, after its last point, when its data does not end where the chunk does.
    void decode(std::uint8_t* records, std::uint64_t count);

    std::uint64_t remaining() const { return m_context.chunk.pointCount - m_decoded; }

private:
    void startPointwise();
    void startLayered();
    void decodePointwise(std::uint8_t* records, std::uint64_t count);
    void decodeLayered(std::uint8_t* records, std::uint64_t count);
    void checkAfterDecode();
    [[noreturn]] void fail(std::uint64_t byteInChunk, const std::string& detail,
                           InputErrorKind kind = InputErrorKind::CorruptData) const;

    const LaszipVlr& m_vlr;
    std::size_t m_recordLength = 0;
    std::vector<std::size_t> m_itemOffsets; // byte of each item inside a record

    std::span<const std::uint8_t> m_bytes;
    ChunkContext m_context;
    std::uint64_t m_decoded = 0;

    // Point-wise: one stream for all items.
    ArithmeticDecoder m_stream;
    std::vector<std::unique_ptr<PointwiseItemDecoder>> m_pointwise;

    // Layered: POINT14 first, then the others; the layers of all items, with where each lies
    // in the chunk and what it holds, for errors.
    std::unique_ptr<Point14Decoder> m_point14;
    std::vector<std::unique_ptr<LayeredItemDecoder>> m_layered; // after POINT14
    std::vector<Layer> m_layers;
    std::vector<std::uint64_t> m_layerStarts;
    std::vector<std::uint64_t> m_layerSizes;
    std::vector<std::string> m_layerNames;
    std::vector<std::uint8_t> m_channels; // each point's scanner channel, for the other items
};

} // namespace omicron::laz
