// Decodes a .oms range's records into a sorted cloud, on every core: positions and the other
// columns copied out, codes recomputed and checked for order. The records are cut into grains
// decoded in parallel; what each grain finds is then checked in file order (within a grain,
// then a grain's first code against the last before it), so the error names the file's first
// bad record, as a record-by-record read would.
#pragma once

#include "formats/oms_format.hpp"
#include "points/morton.hpp"
#include "points/sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace omicron {

class OmsRecordDecoder {
public:
    // Records of `layout` (without the file's uniform columns) with `attributes`, from the
    // file `path` (for errors).
    OmsRecordDecoder(const oms::RecordLayout& layout, AttributeSet attributes, std::string path);

    // Decodes records [0, count) of `block`, the file's records from `first` on, into `out`
    // (a staged range of `count` points, with no span for the file's uniform columns: the
    // cloud stores them once). Throws
    // InputError MalformedValue, at the record's byte, for the first record with a non-finite
    // position or a code below the record's before it (`previousCode` for the first). Returns
    // the last record's code.
    morton::Code decode(const std::uint8_t* block, std::size_t count, std::size_t first,
                        morton::Code previousCode, const SortedCloud::StagedRange& out);

    // Points a grain holds: one task's work.
    static constexpr std::size_t kGrainPoints = 4096;

private:
    // What a grain found: its first bad record (a non-finite position, or a code below the one
    // before it in the grain), and its first and last codes for the checks across grains.
    struct GrainCheck {
        static constexpr std::size_t kNone = SIZE_MAX;
        std::size_t bad = kNone; // index in the block
        bool nonFinite = false;
        morton::Code badCode = 0, codeBefore = 0; // an order error's codes
        morton::Code first = 0, last = 0;
    };

    GrainCheck decodeGrain(const std::uint8_t* block, std::size_t begin, std::size_t end,
                           const SortedCloud::StagedRange& out) const;
    void copyAttributes(const std::uint8_t* block, std::size_t begin, std::size_t end,
                        const SortedCloud::StagedRange& out) const;
    // Throws for the first bad record the checks describe, in file order; returns the block's
    // last code.
    morton::Code throwFirstBadRecord(std::size_t first, morton::Code previousCode) const;

    oms::RecordLayout m_layout;
    AttributeSet m_attributes;
    std::string m_path;
    std::vector<GrainCheck> m_checks; // one per grain of the block being decoded
};

} // namespace omicron
