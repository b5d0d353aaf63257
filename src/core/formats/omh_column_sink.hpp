// Writes a columnar .omh level (version 4's deepest, omh_format.hpp): the points its nodes
// hold, field by field, each field at its column's offset in a file already extended past
// it, then the sparse nodes' splat attributes; hashes each column for the level's checksum.
// A leaf's points are a stretch of the sorted cloud, and in the exact store each of the
// cloud's arrays is a column as the file stores it: the sink writes runs of consecutive
// leaves straight from the cloud's memory, with no encoding. Where `build --save` already
// streamed the columns while the hierarchy was built (omh_column_stream.hpp), only the sparse
// splat attributes are left to write.
#pragma once

#include "build/hierarchy.hpp"
#include "build/octree_node.hpp"
#include "build/splat_estimator.hpp"
#include "formats/omh_format.hpp"
#include "formats/oms_format.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/scratch_bytes.hpp"
#include "io/write_behind.hpp"
#include "points/sorted_cloud.hpp"

#include <cstdint>
#include <vector>

namespace omicron {

// The uniform columns (omh::kUniform* bits) a .omh of `cloud` declares in its header.
std::uint8_t omhUniformColumns(const SortedCloud& cloud);

// Column `column` of the cloud's points as the file stores it, contiguous, straight from the
// cloud's array; null where the cloud does not keep it so (the packed store's positions and
// colours, a uniform LAS column too long for the header).
const std::uint8_t* omhCloudColumn(const SortedCloud& cloud, const omh::Column& column);

// What omh_column_stream wrote: the columns of points [0, points) of `cloud` from byte
// `offset` (omh::Header::columnsOffset), laid out as omh::columnSpans puts them, and each
// column's XXH3-64. Empty (no cloud) when nothing was streamed.
struct OmhStreamedColumns {
    const SortedCloud* cloud = nullptr;
    std::uint64_t offset = 0;
    std::uint64_t points = 0;
    std::vector<omh::Column> columns;
    std::vector<std::uint64_t> digests;
};

class OmhColumnSink {
public:
    // `level` of `hierarchy`, a columnar one of `header` (its offsets assigned). `streamed`
    // (may be null) is used when it holds exactly what this level's columns must be (the
    // level's nodes hold the whole cloud in order, a stretch each, laid out as here);
    // otherwise the sink writes them.
    OmhColumnSink(AtomicFileWriter& file, const Hierarchy& hierarchy, const omh::Header& header,
                  int level, const OmhStreamedColumns* streamed);

    // Whether the streamed columns were taken (nothing of them is written again).
    bool usesStreamed() const { return m_streamed; }

    // Every point `node` holds, in order after the nodes added before; keeps its splat
    // attributes when it is a sparse node.
    void addNode(const OctreeNode& node, const NodeSplats& splats);

    // Writes what is pending and the sparse nodes' splat attributes; returns the level's
    // payload checksum (omh::columnarChecksum).
    std::uint64_t finishSection();

private:
    void flushRun();
    // Hashes and writes `count` points' values of column `c`.
    void writeColumn(std::size_t c, const std::uint8_t* bytes, std::size_t count);
    void gather(std::size_t c, const OctreeNode& node, std::uint8_t* out) const;

    AtomicFileWriter& m_file;
    const SortedCloud& m_cloud;
    std::uint64_t m_sparseOffset;
    bool m_estimatedNormal;
    std::vector<omh::Column> m_columns;
    std::vector<omh::ColumnSpan> m_spans;    // per column, absolute file offsets
    std::vector<const std::uint8_t*> m_data; // per column: omhCloudColumn (null: gathered)
    bool m_contiguous = false;               // every column is in m_data
    std::vector<std::uint64_t> m_at;         // per column: where the next bytes go
    std::vector<oms::PayloadChecksum> m_checksums;
    std::vector<WriteBehind> m_writeBehind;
    std::vector<std::uint64_t> m_streamedDigests;
    bool m_streamed = false;
    std::vector<std::uint8_t> m_sparseSplats;
    // Consecutive held points not yet written: cloud points [m_runBegin, m_runEnd).
    std::size_t m_runBegin = 0;
    std::size_t m_runEnd = 0;
    ScratchBytes m_gathered;
};

} // namespace omicron
