// Where the LAS reader's point records come from: the point data as an uncompressed file
// stores it (las_file_records), or decoded from a LAZ file's chunks (io/laz/laz_records). A
// source delivers standard LAS point records in file order; the reader turns them into points.
#pragma once

#include "io/input_error.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace omicron {

struct LasRecordBlock {
    const std::uint8_t* records = nullptr; // `count` whole records of the header's length
    std::uint64_t count = 0;
    std::uint64_t firstIndex = 0; // index of records[0] in the file, counting from 0
    std::uint64_t endByte = 0;    // how far into the file the source has read (progress)
};

class LasRecordSource {
public:
    virtual ~LasRecordSource() = default;

    // Visits every record once, in file order, in blocks valid during the call, until `visit`
    // returns false. May be called again (a bounds pre-pass, then the read). Throws InputError.
    using BlockVisitor = std::function<bool(const LasRecordBlock&)>;
    virtual void forEachBlock(const BlockVisitor& visit) = 0;

    // Visits up to `maxRecords` records spread over the file (the colour-depth sample) and
    // returns how many it visited. Throws InputError.
    using RecordVisitor = std::function<void(const std::uint8_t* record)>;
    virtual std::uint64_t sampleRecords(std::uint64_t maxRecords, const RecordVisitor& visit) = 0;

    // A cloud with a level of detail of its own (COPC): visits the records of its top levels
    // (at most about `maxRecords`, whole levels), a uniform sample of the whole cloud, and
    // returns how many. 0 for other sources. Throws InputError.
    virtual std::uint64_t hierarchyPreview(std::uint64_t /*maxRecords*/,
                                           const RecordVisitor& /*visit*/) {
        return 0;
    }

    // Where record `index` is, for an error about it: the byte and how to name it.
    virtual InputLocation recordLocation(std::uint64_t index) const = 0;
    virtual std::string recordName(std::uint64_t index) const = 0;

    // What the format detail adds about the storage ("" for plain records).
    virtual std::string describe() const = 0;
};

} // namespace omicron
