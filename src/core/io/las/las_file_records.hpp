// The point records of an uncompressed LAS file, read in blocks of whole records.
#pragma once

#include "io/file_stream.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_record_source.hpp"

#include <memory>

namespace omicron {

class LasFileRecords final : public LasRecordSource {
public:
    // `header` was read from `stream` by las::readHeader (so the file holds every record).
    LasFileRecords(std::unique_ptr<FileStream> stream, const las::Header& header);

    void forEachBlock(const BlockVisitor& visit) override;
    // Records at evenly spaced indices.
    std::uint64_t sampleRecords(std::uint64_t maxRecords, const RecordVisitor& visit) override;
    InputLocation recordLocation(std::uint64_t index) const override;
    std::string recordName(std::uint64_t index) const override;
    std::string describe() const override { return {}; }

private:
    std::unique_ptr<FileStream> m_stream;
    las::Header m_header;
};

} // namespace omicron
