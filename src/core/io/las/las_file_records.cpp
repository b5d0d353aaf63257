#include "io/las/las_file_records.hpp"

#include <algorithm>
#include <tbb/task_group.h>

namespace omicron {

namespace {
// Records are read in blocks of whole records of about this size.
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;
} // namespace

LasFileRecords::LasFileRecords(std::unique_ptr<FileStream> stream, const las::Header& header)
    : m_stream(std::move(stream)), m_header(header) {}

void LasFileRecords::forEachBlock(const BlockVisitor& visit) {
    const std::uint64_t stride = m_header.recordLength;
    const std::uint64_t recordsPerBlock = std::max<std::uint64_t>(1, kBlockBytes / stride);
    for (std::vector<std::uint8_t>& block : m_blocks) {
        block.resize(static_cast<std::size_t>(recordsPerBlock * stride));
    }
    m_stream->seek(m_header.pointDataOffset);
    const auto readBlock = [&](std::uint64_t first) {
        const std::uint64_t count = std::min(recordsPerBlock, m_header.pointCount - first);
        std::vector<std::uint8_t>& block = m_blocks[(first / recordsPerBlock) % 2];
        m_stream->readExact(block.data(), static_cast<std::size_t>(count * stride),
                            "point records " + std::to_string(first) + " to " +
                                std::to_string(first + count - 1) + " (counting from 0, " +
                                std::to_string(stride) + " bytes each)");
    };
    // Block k + 1 is read (a copy out of the page cache, as long as parsing block k) while
    // block k is visited, by a worker thread where one is free.
    tbb::task_group readAhead;
    const auto finishReadAhead = [&readAhead] {
        try {
            readAhead.wait();
        } catch (...) { // the visit's error, which came first, is the one reported
        }
    };
    if (m_header.pointCount > 0) {
        readBlock(0);
    }
    for (std::uint64_t first = 0; first < m_header.pointCount; first += recordsPerBlock) {
        const std::uint64_t count = std::min(recordsPerBlock, m_header.pointCount - first);
        const std::uint64_t next = first + recordsPerBlock;
        if (next < m_header.pointCount) {
            readAhead.run([&readBlock, next] { readBlock(next); });
        }
        bool more;
        try {
            more = visit({m_blocks[(first / recordsPerBlock) % 2].data(), count, first,
                          m_header.recordOffset(first + count)});
        } catch (...) {
            finishReadAhead();
            throw;
        }
        if (!more) {
            finishReadAhead();
            return;
        }
        readAhead.wait(); // rethrows the next block's read error
    }
}

std::uint64_t LasFileRecords::sampleRecords(std::uint64_t maxRecords, const RecordVisitor& visit) {
    const std::uint64_t samples = std::min(maxRecords, m_header.pointCount);
    std::vector<std::uint8_t> record(m_header.recordLength);
    for (std::uint64_t s = 0; s < samples; ++s) {
        const std::uint64_t index = s * m_header.pointCount / samples;
        m_stream->seek(m_header.recordOffset(index));
        m_stream->readExact(record.data(), record.size(),
                            "point record " + std::to_string(index) + " (counting from 0)");
        visit(record.data());
    }
    return samples;
}

InputLocation LasFileRecords::recordLocation(std::uint64_t index) const {
    return InputLocation::byte(m_header.recordOffset(index));
}

std::string LasFileRecords::recordName(std::uint64_t index) const {
    return "point record " + std::to_string(index) + " (counting from 0)";
}

} // namespace omicron
