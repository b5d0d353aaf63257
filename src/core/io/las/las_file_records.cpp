#include "io/las/las_file_records.hpp"

#include <algorithm>

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
    m_block.resize(static_cast<std::size_t>(recordsPerBlock * stride));
    m_stream->seek(m_header.pointDataOffset);
    for (std::uint64_t first = 0; first < m_header.pointCount; first += recordsPerBlock) {
        const std::uint64_t count = std::min(recordsPerBlock, m_header.pointCount - first);
        m_stream->readExact(m_block.data(), static_cast<std::size_t>(count * stride),
                            "point records " + std::to_string(first) + " to " +
                                std::to_string(first + count - 1) + " (counting from 0, " +
                                std::to_string(stride) + " bytes each)");
        if (!visit({m_block.data(), count, first, m_header.recordOffset(first + count)})) {
            return;
        }
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
