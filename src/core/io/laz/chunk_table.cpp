#include "io/laz/chunk_table.hpp"

#include "io/input_error.hpp"
#include "io/laz/arithmetic_decoder.hpp"
#include "io/laz/integer_decoder.hpp"

#include <algorithm>
#include <cstring>

namespace omicron::laz {

namespace {

// The coded entries need at most a few bytes each (a magnitude class, a corrector and raw low
// bits per number, two numbers a chunk); this bounds what is read, whatever follows the table.
constexpr std::uint64_t kMaxCodedBytesPerChunk = 32;
constexpr std::uint64_t kCodedBytesSlack = 64;

class LayoutReader {
public:
    LayoutReader(FileStream& stream, const LaszipVlr& vlr, const PointDataExtent& data)
        : m_stream(stream), m_vlr(vlr), m_data(data) {}

    ChunkLayout read() {
        ChunkLayout layout;
        if (m_vlr.compressor == Compressor::Pointwise) {
            // LAZ 1.0: the whole point data is one chunk, without a table.
            layout.chunks.push_back(
                {0, m_data.pointCount, m_data.offset, m_data.end - m_data.offset});
            return layout;
        }
        layout.tableOffset = readTableOffset();
        const std::uint32_t count = readTableHeader(layout.tableOffset);
        layout.chunks = decodeEntries(layout.tableOffset, count);
        return layout;
    }

private:
    [[noreturn]] void fail(InputErrorKind kind, std::uint64_t byte,
                           const std::string& detail) const {
        throw InputError(kind, m_stream.path(), InputLocation::byte(byte), detail);
    }

    std::uint64_t chunksStart() const { return m_data.offset + 8; }

    template <typename T> T readAt(std::uint64_t at, const std::string& what) {
        T value;
        m_stream.seek(at);
        m_stream.readExact(&value, sizeof value, what);
        return value;
    }

    std::uint64_t readTableOffset() {
        auto offset = readAt<std::int64_t>(m_data.offset, "the offset of the LAZ chunk table");
        std::uint64_t pointerAt = m_data.offset;
        if (offset == -1) {
            // Written by a compressor that could not seek back: the offset ends the file.
            if (m_stream.size() < chunksStart() + 8) {
                fail(InputErrorKind::Truncated, m_stream.size(),
                     "expected the offset of the LAZ chunk table in the file's last 8 bytes, "
                     "but the file ends at byte " +
                         std::to_string(m_stream.size()));
            }
            pointerAt = m_stream.size() - 8;
            offset = readAt<std::int64_t>(pointerAt, "the offset of the LAZ chunk table");
        }
        const auto table = static_cast<std::uint64_t>(offset);
        if (offset < 0 || table < chunksStart() || table > m_data.end) {
            if (offset >= 0 && table > m_data.end && table >= m_stream.size()) {
                fail(InputErrorKind::Truncated, pointerAt,
                     "the LAZ chunk table should start at byte " + std::to_string(table) +
                         ", but the file ends at byte " + std::to_string(m_stream.size()) +
                         ": the file is truncated");
            }
            fail(InputErrorKind::CorruptData, pointerAt,
                 "the LAZ chunk table offset " + std::to_string(offset) +
                     " lies outside the point data (bytes " + std::to_string(chunksStart()) +
                     " to " + std::to_string(m_data.end) + ")");
        }
        if (table == chunksStart()) {
            fail(InputErrorKind::CorruptData, pointerAt,
                 "the LAZ file has no chunks and no chunk table (its compressor was interrupted "
                 "before writing them)");
        }
        return table;
    }

    std::uint32_t readTableHeader(std::uint64_t table) {
        if (table + 8 > m_stream.size()) {
            fail(InputErrorKind::Truncated, table,
                 "expected the LAZ chunk table (8 bytes and its entries) at byte " +
                     std::to_string(table) + ", but the file ends at byte " +
                     std::to_string(m_stream.size()) + ": the file is truncated");
        }
        const auto version = readAt<std::uint32_t>(table, "the LAZ chunk table's version");
        if (version != 0) {
            fail(InputErrorKind::CorruptData, table,
                 "LAZ chunk table version " + std::to_string(version) + ", expected 0");
        }
        const auto count = readAt<std::uint32_t>(table + 4, "the LAZ chunk count");
        // Every chunk starts with a raw point record.
        const std::uint64_t room = (table - chunksStart()) / m_data.recordLength;
        if (count == 0 || count > room) {
            fail(InputErrorKind::CorruptData, table + 4,
                 "the LAZ chunk table lists " + std::to_string(count) + " chunks, expected 1 to " +
                     std::to_string(room) + " (the " + std::to_string(table - chunksStart()) +
                     " bytes of chunks hold at most that many " +
                     std::to_string(m_data.recordLength) + "-byte first points)");
        }
        if (!m_vlr.variableChunks()) {
            const std::uint64_t expected =
                (m_data.pointCount + m_vlr.chunkSize - 1) / m_vlr.chunkSize;
            if (count != expected) {
                fail(InputErrorKind::CountMismatch, table + 4,
                     "the LAZ chunk table lists " + std::to_string(count) + " chunks of " +
                         std::to_string(m_vlr.chunkSize) + " points, but the header declares " +
                         std::to_string(m_data.pointCount) + " points, which make " +
                         std::to_string(expected) + " chunks");
            }
        }
        return count;
    }

    std::vector<Chunk> decodeEntries(std::uint64_t table, std::uint32_t count) {
        const std::uint64_t codedAt = table + 8;
        const std::uint64_t available = m_stream.size() - codedAt;
        std::vector<std::uint8_t> coded(static_cast<std::size_t>(
            std::min(available, count * kMaxCodedBytesPerChunk + kCodedBytesSlack)));
        m_stream.seek(codedAt);
        m_stream.readExact(coded.data(), coded.size(), "the LAZ chunk table's entries");

        ArithmeticDecoder decoder;
        decoder.start(coded.data(), coded.data() + coded.size());
        IntegerDecoder numbers(32, 2);
        std::vector<std::uint32_t> pointCounts(count);
        std::vector<std::uint32_t> byteCounts(count);
        std::uint32_t lastPoints = 0;
        std::uint32_t lastBytes = 0;
        for (std::uint32_t i = 0; i < count; ++i) {
            if (m_vlr.variableChunks()) {
                lastPoints = static_cast<std::uint32_t>(
                    numbers.decode(decoder, static_cast<std::int32_t>(lastPoints), 0));
                pointCounts[i] = lastPoints;
            }
            lastBytes = static_cast<std::uint32_t>(
                numbers.decode(decoder, static_cast<std::int32_t>(lastBytes), 1));
            byteCounts[i] = lastBytes;
        }
        if (decoder.overran()) {
            fail(InputErrorKind::CorruptData, table,
                 "the LAZ chunk table is truncated or corrupt: its " + std::to_string(count) +
                     " entries need more than the " + std::to_string(coded.size()) +
                     " bytes after it");
        }
        return place(table, pointCounts, byteCounts);
    }

    // Lays the chunks out one after the other from the start of the point data.
    std::vector<Chunk> place(std::uint64_t table, const std::vector<std::uint32_t>& pointCounts,
                             const std::vector<std::uint32_t>& byteCounts) const {
        std::vector<Chunk> chunks(byteCounts.size());
        std::uint64_t offset = chunksStart();
        std::uint64_t firstPoint = 0;
        const std::uint64_t total = m_data.pointCount;
        for (std::size_t i = 0; i < chunks.size(); ++i) {
            Chunk& chunk = chunks[i];
            const std::string name =
                "LAZ chunk " + std::to_string(i) + " of " + std::to_string(chunks.size());
            chunk.offset = offset;
            chunk.bytes = byteCounts[i];
            chunk.firstPoint = firstPoint;
            chunk.pointCount = m_vlr.variableChunks()
                                   ? pointCounts[i]
                                   : std::min<std::uint64_t>(m_vlr.chunkSize, total - firstPoint);
            if (chunk.bytes < m_data.recordLength || offset + chunk.bytes > table) {
                fail(InputErrorKind::CorruptData, table,
                     "the chunk table is corrupt: " + name + " at byte " + std::to_string(offset) +
                         " has " + std::to_string(chunk.bytes) + " bytes, expected " +
                         std::to_string(m_data.recordLength) + " to " +
                         std::to_string(table - offset) + " (up to the chunk table)");
            }
            if (chunk.pointCount == 0) {
                fail(InputErrorKind::CorruptData, table,
                     "the chunk table is corrupt: " + name + " at byte " + std::to_string(offset) +
                         " holds 0 points");
            }
            offset += chunk.bytes;
            firstPoint += chunk.pointCount;
        }
        if (offset != table) {
            fail(InputErrorKind::CorruptData, table,
                 "the chunk table is corrupt: its chunks end at byte " + std::to_string(offset) +
                     ", but the table starts at byte " + std::to_string(table));
        }
        if (firstPoint != total) {
            fail(InputErrorKind::CountMismatch, table,
                 "the LAZ chunks hold " + std::to_string(firstPoint) +
                     " points, but the header declares " + std::to_string(total));
        }
        return chunks;
    }

    FileStream& m_stream;
    const LaszipVlr& m_vlr;
    const PointDataExtent& m_data;
};

} // namespace

ChunkLayout readChunkLayout(FileStream& stream, const LaszipVlr& vlr, const PointDataExtent& data) {
    return LayoutReader(stream, vlr, data).read();
}

} // namespace omicron::laz
