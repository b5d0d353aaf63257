// Decodes .omh point records into a node-order cloud and its stored splat attributes. The
// whole-file loader (a level at a time, omh_reader) and the pager (a node at a time,
// omh_pager) share it, so a record means the same to both.
#pragma once

#include "build/stored_splats.hpp"
#include "formats/omh_format.hpp"
#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "points/morton.hpp"
#include "points/sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

class OmhRecordDecoder {
public:
    OmhRecordDecoder(const omh::Header& header, SortedCloud& cloud, StoredSplats& splats);

    // Writes `count` records, all held by the node `nodeCode` of `level`, to the cloud's
    // points [point, point + count). Returns the index of the first record whose position is
    // not finite or lies outside the node's cell, or `count` when every record is good (the
    // bad ones are written too: the caller decides whether the node is used).
    std::size_t store(const std::uint8_t* records, std::size_t count, std::size_t point,
                      morton::Code nodeCode, int level) const;

    // Version 3: the splat attributes of `count` points of a sparse node, as its level stores
    // them after its records (omh::splatBytes each), for the cloud's points [point, ...).
    void storeSparseSplats(const std::uint8_t* bytes, std::size_t count, std::size_t point) const;

    std::size_t recordBytes() const { return m_layout.bytes; }

    // A columnar level (version 4's deepest): reads its points [inLevel, inLevel + count)
    // from each of its columns in `stream` straight into the cloud's points [point, ...),
    // hashing each column's bytes into checksums[column] when `checksums` is given.
    void readColumns(FileStream& stream, int level, std::uint64_t inLevel, std::size_t count,
                     std::size_t point, std::vector<oms::PayloadChecksum>* checksums) const;
    // The first of the cloud's points [point, point + count) whose position is not finite or
    // lies outside the cell of the node `nodeCode` of `level`, as an offset from `point`;
    // `count` when they are all good.
    std::size_t firstMisplaced(std::size_t point, std::size_t count, morton::Code nodeCode,
                               int level) const;

    // The error for record `recordInLevel` of `level` that store() found outside the cell of
    // its node `nodeCode`, naming the file, the byte and the section: both loaders' words.
    InputError misplaced(int level, std::uint64_t recordInLevel, morton::Code nodeCode) const;

private:
    const omh::Header& m_header; // outlives the decoder
    omh::RecordLayout m_layout;
    AttributeSet m_attributes;
    bool m_estimatedNormals;
    SortedCloud& m_cloud;
    StoredSplats& m_splats;
};

} // namespace omicron
