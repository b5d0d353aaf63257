#include "io/laz/laz_records.hpp"

#include "io/laz/chunk_decoder.hpp"
#include "io/laz/chunk_table.hpp"
#include "io/laz/copc_hierarchy.hpp"
#include "io/laz/laszip_vlr.hpp"
#include "io/scratch_bytes.hpp"

#include <algorithm>
#include <exception>
#include <optional>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <vector>

namespace omicron {

namespace {

class LazRecords final : public LasRecordSource {
public:
    LazRecords(std::unique_ptr<FileStream> stream, const las::Header& header,
               const LazStreaming& streaming)
        : m_stream(std::move(stream)), m_header(header), m_streaming(streaming) {
        std::vector<std::uint8_t> payload(header.laszipRecordLength);
        m_stream->seek(header.laszipRecordOffset);
        m_stream->readExact(payload.data(), payload.size(), "the 'laszip encoded' record");
        m_vlr = laz::parseLaszipVlr(payload, m_stream->path(), header.laszipRecordOffset,
                                    header.pointFormat, header.recordLength);
        const laz::PointDataExtent data{header.pointDataOffset, m_stream->size(), header.pointCount,
                                        header.recordLength};
        m_layout = laz::readChunkLayout(*m_stream, m_vlr, data);
        m_copc = laz::readCopcInfo(*m_stream, header);
    }

    // COPC: the chunks of the hierarchy's top nodes, decoded whole (each node is one chunk).
    std::uint64_t hierarchyPreview(std::uint64_t maxRecords, const RecordVisitor& visit) override {
        if (!m_copc) {
            return 0;
        }
        const std::vector<laz::CopcNode> nodes =
            laz::readCopcTopNodes(*m_stream, *m_copc, maxRecords);
        const std::vector<laz::Chunk>& chunks = m_layout.chunks;
        std::uint64_t visited = 0;
        ScratchBytes compressed;
        std::vector<std::uint8_t> records;
        for (const laz::CopcNode& node : nodes) {
            const auto chunk = std::lower_bound(
                chunks.begin(), chunks.end(), node.offset,
                [](const laz::Chunk& c, std::uint64_t offset) { return c.offset < offset; });
            if (chunk == chunks.end() || chunk->offset != node.offset ||
                chunk->pointCount != node.pointCount) {
                throw InputError(InputErrorKind::CorruptData, m_stream->path(),
                                 InputLocation::byte(node.offset),
                                 "COPC: the hierarchy's node " + std::to_string(node.level) +
                                     "-" + std::to_string(node.x) + "-" + std::to_string(node.y) +
                                     "-" + std::to_string(node.z) + " (" +
                                     std::to_string(node.pointCount) + " points at byte " +
                                     std::to_string(node.offset) +
                                     ") is not a chunk of the chunk table");
            }
            const std::size_t c = static_cast<std::size_t>(chunk - chunks.begin());
            if (decodedBytes(c) > m_streaming.batchBytes) {
                continue;
            }
            const std::span<const std::uint8_t> bytes = readChunks(c, c + 1, compressed);
            laz::ChunkDecoder decoder(m_vlr);
            decoder.start(bytes, context(c));
            records.resize(static_cast<std::size_t>(decodedBytes(c)));
            decoder.decode(records.data(), chunk->pointCount);
            for (std::uint64_t i = 0; i < chunk->pointCount; ++i) {
                visit(records.data() + i * m_header.recordLength);
            }
            visited += chunk->pointCount;
        }
        return visited;
    }

    void forEachBlock(const BlockVisitor& visit) override {
        std::size_t next = 0;
        while (next < m_layout.chunks.size()) {
            if (decodedBytes(next) > m_streaming.batchBytes) {
                if (!streamLargeChunk(next, visit)) {
                    return;
                }
                ++next;
                continue;
            }
            std::size_t end = next + 1;
            std::uint64_t batchBytes = chunkBytes(next);
            while (end < m_layout.chunks.size() && decodedBytes(end) <= m_streaming.batchBytes &&
                   batchBytes + chunkBytes(end) <= m_streaming.batchBytes) {
                batchBytes += chunkBytes(end);
                ++end;
            }
            if (!decodeBatch(next, end, visit)) {
                return;
            }
            next = end;
        }
    }

    // The raw first record of chunks spread over the file, then the first chunk's records
    // (unless it is too large to read whole at opening).
    std::uint64_t sampleRecords(std::uint64_t maxRecords, const RecordVisitor& visit) override {
        const std::vector<laz::Chunk>& chunks = m_layout.chunks;
        const std::uint64_t spread =
            std::min<std::uint64_t>(chunks.size(), std::max<std::uint64_t>(1, maxRecords / 2));
        std::vector<std::uint8_t> record(m_header.recordLength);
        for (std::uint64_t s = 0; s < spread && s < maxRecords; ++s) {
            const laz::Chunk& chunk = chunks[s * chunks.size() / spread];
            m_stream->seek(chunk.offset);
            m_stream->readExact(record.data(), record.size(), "the first point of a LAZ chunk");
            visit(record.data());
        }
        std::uint64_t visited = std::min(spread, maxRecords);
        const std::uint64_t prefix = std::min(chunks[0].pointCount, maxRecords - visited + 1);
        if (prefix > 1 && decodedBytes(0) <= m_streaming.batchBytes) {
            ScratchBytes compressed;
            const std::span<const std::uint8_t> bytes = readChunks(0, 1, compressed);
            laz::ChunkDecoder decoder(m_vlr);
            decoder.start(bytes, context(0));
            std::vector<std::uint8_t> records(prefix * m_header.recordLength);
            decoder.decode(records.data(), prefix);
            for (std::uint64_t i = 1; i < prefix; ++i) { // record 0 was sampled raw
                visit(records.data() + i * m_header.recordLength);
                ++visited;
            }
        }
        return visited;
    }

    InputLocation recordLocation(std::uint64_t index) const override {
        return InputLocation::byte(chunkOf(index).offset);
    }

    std::string recordName(std::uint64_t index) const override {
        const laz::Chunk& chunk = chunkOf(index);
        const std::size_t c = static_cast<std::size_t>(&chunk - m_layout.chunks.data());
        return "point record " + std::to_string(index) + " (counting from 0, in LAZ chunk " +
               std::to_string(c) + " of " + std::to_string(m_layout.chunks.size()) +
               " starting at byte " + std::to_string(chunk.offset) + ")";
    }

    std::string describe() const override {
        std::string text = m_vlr.describe() + ", " + std::to_string(m_layout.chunks.size()) +
                           " chunk" + (m_layout.chunks.size() == 1 ? "" : "s");
        if (m_vlr.compressor == laz::Compressor::Pointwise) {
            return text;
        }
        text += m_vlr.variableChunks() ? " of variable size"
                                       : " of " + std::to_string(m_vlr.chunkSize) + " points";
        return m_copc ? text + ", COPC hierarchy" : text;
    }

private:
    std::uint64_t decodedBytes(std::size_t chunk) const {
        return m_layout.chunks[chunk].pointCount * m_header.recordLength;
    }
    std::uint64_t chunkBytes(std::size_t chunk) const {
        return m_layout.chunks[chunk].bytes + decodedBytes(chunk);
    }

    laz::ChunkContext context(std::size_t chunk) const {
        laz::ChunkContext c;
        c.path = &m_stream->path();
        c.index = chunk;
        c.count = m_layout.chunks.size();
        c.chunk = m_layout.chunks[chunk];
        c.exactEnd = m_layout.tableOffset != 0;
        return c;
    }

    const laz::Chunk& chunkOf(std::uint64_t index) const {
        const auto& chunks = m_layout.chunks;
        auto after = std::upper_bound(
            chunks.begin(), chunks.end(), index,
            [](std::uint64_t i, const laz::Chunk& chunk) { return i < chunk.firstPoint; });
        return after == chunks.begin() ? chunks.front() : *(after - 1);
    }

    // The compressed bytes of chunks [first, end): contiguous in the file, one read into `into`.
    std::span<const std::uint8_t> readChunks(std::size_t first, std::size_t end,
                                             ScratchBytes& into) {
        const laz::Chunk& last = m_layout.chunks[end - 1];
        const std::uint64_t begin = m_layout.chunks[first].offset;
        const std::span<std::uint8_t> bytes =
            into.take(static_cast<std::size_t>(last.offset + last.bytes - begin));
        m_stream->seek(begin);
        m_stream->readExact(bytes.data(), bytes.size(),
                            "LAZ chunks " + std::to_string(first) + " to " +
                                std::to_string(end - 1));
        return bytes;
    }

    // Decodes chunks [first, end) in parallel and visits them in order. A chunk that fails is
    // reported after every chunk before it was delivered, so the error does not depend on
    // which thread finished first.
    bool decodeBatch(std::size_t first, std::size_t end, const BlockVisitor& visit) {
        const std::span<const std::uint8_t> compressed = readChunks(first, end, m_compressed);
        const std::uint64_t base = m_layout.chunks[first].offset;
        std::vector<std::uint64_t> recordStart(end - first + 1, 0);
        for (std::size_t c = first; c < end; ++c) {
            recordStart[c - first + 1] = recordStart[c - first] + decodedBytes(c);
        }
        // Every byte is written by its chunk's decoder; a chunk that fails is never visited.
        const std::span<std::uint8_t> records =
            m_records.take(static_cast<std::size_t>(recordStart.back()));
        std::vector<std::exception_ptr> errors(end - first);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(first, end, 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t c = range.begin(); c != range.end(); ++c) {
                                  try {
                                      const laz::Chunk& chunk = m_layout.chunks[c];
                                      laz::ChunkDecoder decoder(m_vlr);
                                      decoder.start({compressed.data() + (chunk.offset - base),
                                                     static_cast<std::size_t>(chunk.bytes)},
                                                    context(c));
                                      decoder.decode(records.data() + recordStart[c - first],
                                                     chunk.pointCount);
                                  } catch (...) {
                                      errors[c - first] = std::current_exception();
                                  }
                              }
                          });
        for (std::size_t c = first; c < end; ++c) {
            if (errors[c - first]) {
                std::rethrow_exception(errors[c - first]);
            }
            const laz::Chunk& chunk = m_layout.chunks[c];
            if (!visit({records.data() + recordStart[c - first], chunk.pointCount, chunk.firstPoint,
                        chunk.offset + chunk.bytes})) {
                return false;
            }
        }
        return true;
    }

    // A chunk too large for a batch (LAZ 1.0's single chunk, or a huge variable chunk): its
    // compressed bytes (at most the file) and one slice of records at a time.
    bool streamLargeChunk(std::size_t c, const BlockVisitor& visit) {
        const laz::Chunk& chunk = m_layout.chunks[c];
        const std::span<const std::uint8_t> compressed = readChunks(c, c + 1, m_compressed);
        laz::ChunkDecoder decoder(m_vlr);
        decoder.start(compressed, context(c));
        const std::uint64_t sliceRecords =
            std::max<std::uint64_t>(1, m_streaming.sliceBytes / m_header.recordLength);
        const std::span<std::uint8_t> records = m_records.take(static_cast<std::size_t>(
            std::min(sliceRecords, chunk.pointCount) * m_header.recordLength));
        for (std::uint64_t done = 0; done < chunk.pointCount;) {
            const std::uint64_t count = std::min(sliceRecords, chunk.pointCount - done);
            decoder.decode(records.data(), count);
            // Progress within the chunk: as far as the slice's share of its bytes.
            const std::uint64_t endByte =
                chunk.offset + chunk.bytes * (done + count) / chunk.pointCount;
            if (!visit({records.data(), count, chunk.firstPoint + done, endByte})) {
                return false;
            }
            done += count;
        }
        return true;
    }

    std::unique_ptr<FileStream> m_stream;
    las::Header m_header;
    LazStreaming m_streaming;
    laz::LaszipVlr m_vlr;
    laz::ChunkLayout m_layout;
    std::optional<laz::CopcInfo> m_copc; // a COPC file's info record
    // Kept from batch to batch: a LAZ file of many batches faults its buffers in once.
    ScratchBytes m_compressed;
    ScratchBytes m_records;
};

} // namespace

std::unique_ptr<LasRecordSource> openLazRecords(std::unique_ptr<FileStream> stream,
                                                const las::Header& header,
                                                const LazStreaming& streaming) {
    return std::make_unique<LazRecords>(std::move(stream), header, streaming);
}

} // namespace omicron
