// Encodes the points a .omh level holds into its point records (position, the cloud's
// normal/colour/intensity, splat radius and estimated normal) a block at a time, hashes them
// for the level's checksum and hands each full block to the file: appended, or written at the
// level's own offset when several levels are filled side by side (omh_payload_sweep).
#pragma once

#include "build/octree_node.hpp"
#include "build/splat_estimator.hpp"
#include "formats/omh_format.hpp"
#include "formats/oms_format.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/scratch_bytes.hpp"
#include "io/write_behind.hpp"
#include "points/sorted_cloud.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace omicron {

// Encodes the records of `node`'s held points [first, last) with their splat attributes into
// `out` ((last - first) * layout.bytes bytes): the work of OmhRecordSink::addNode, callable on
// any thread, so that a level's records can be encoded in parallel and written in order.
void encodeOmhRecords(const SortedCloud& cloud, const omh::RecordLayout& layout,
                      const OctreeNode& node, const NodeSplats& splats, std::uint32_t first,
                      std::uint32_t last, std::uint8_t* out);

// Appends the splat attributes of `node`'s points to `out` (omh::splatBytes each, as a
// version 3 level stores them after its records) when it is a sparse node; nothing otherwise.
void appendOmhSparseSplats(std::vector<std::uint8_t>& out, const OctreeNode& node,
                           const NodeSplats& splats, bool estimatedNormal);

class OmhRecordSink {
public:
    // Appends to `file`.
    OmhRecordSink(AtomicFileWriter& file, const SortedCloud& cloud, const omh::RecordLayout& layout);
    // Writes at `offset` onwards (inside a region made by AtomicFileWriter::extendTo), and
    // lets what it wrote leave the page cache as it goes: a level of a multi-gigabyte file is
    // written once and not read back.
    OmhRecordSink(AtomicFileWriter& file, const SortedCloud& cloud, const omh::RecordLayout& layout,
                  std::uint64_t offset);

    // One held point (a SortedCloud index) and its splat attributes; `estimatedNormal` is
    // stored only when the layout has room for it.
    void add(std::uint32_t index, std::uint16_t encodedRadius, std::uint32_t estimatedNormal);
    // Every point `node` holds, with the node's splat attributes, in order; from version 3
    // the attributes are kept for the section's end when the node stores them (addSparseSplats)
    // and not read otherwise (they may be empty).
    void addNode(const OctreeNode& node, const NodeSplats& splats);
    // Version 3: keeps the splat attributes of `node`, when it is a sparse node, to be written
    // after the section's records (finishSection). Nothing otherwise.
    void addSparseSplats(const OctreeNode& node, const NodeSplats& splats);

    // Records encoded elsewhere (encodeOmhRecords), in order after what was added before.
    void addEncoded(const std::uint8_t* records, std::size_t bytes);

    // Writes what is pending, then the sparse nodes' splat attributes kept, and returns the
    // checksum of everything since the last call.
    std::uint64_t finishSection();

private:
    void flush();
    // Hashes `bytes` and writes them after what was written before.
    void write(const std::uint8_t* records, std::size_t bytes);

    AtomicFileWriter& m_file;
    const SortedCloud& m_cloud;
    omh::RecordLayout m_layout;
    ScratchBytes m_block; // m_blockBytes once used, never zeroed: a top level's few records
                          // fault in only their own pages
    std::size_t m_blockBytes = 0;
    std::size_t m_used = 0;
    std::vector<std::uint8_t> m_sparseSplats; // version 3: written at the section's end
    std::unique_ptr<oms::PayloadChecksum> m_checksum;
    bool m_positional = false;
    std::uint64_t m_at = 0;    // positional: where the next block goes
    WriteBehind m_writeBehind; // positional: what it wrote leaves the page cache
};

} // namespace omicron
