#include "formats/omh_writer.hpp"

#include "formats/omh_payload_sweep.hpp"
#include "formats/omh_record_sink.hpp"
#include "formats/omh_top_levels.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/file_stream.hpp"

#include <algorithm>
#include <cstring>
#include <optional>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <vector>

namespace omicron {

namespace {

// The deep levels are written in one sweep over the cloud (omh_payload_sweep), a batch of
// subtrees holding at most this many points at a time: their splat attributes are held until
// written. In memory, batches are small so that the last one, whose writing nothing overlaps,
// is short (measured on 24.2 M points: 1 Mi saves 3 % of build --save against 4 Mi; 512 Ki
// no more). For a cloud in a scratch file, an eighth of the budget's worth up to the second
// constant, or a 32nd of it when that is more, up to the third: fewer, longer reads.
constexpr std::uint64_t kInMemorySweepBatchPoints = std::uint64_t{1} << 20;
constexpr std::uint64_t kSweepBatchPoints = std::uint64_t{4} << 20;
constexpr std::uint64_t kFileBackedSweepBatchPoints = std::uint64_t{64} << 20;

template <typename T> void store(std::uint8_t* at, const T& value) {
    std::memcpy(at, &value, sizeof(T));
}

std::uint8_t childMask(const Hierarchy& hierarchy, int level, const OctreeNode& node) {
    std::uint8_t mask = 0;
    for (std::uint32_t c = 0; c < node.childCount; ++c) {
        const OctreeNode& child = hierarchy.node(level + 1, node.firstChild + c);
        mask = static_cast<std::uint8_t>(mask | (1u << (child.code & 7u)));
    }
    return mask;
}

// The splat attributes of the nodes in file order, estimated a batch of nodes at a time in
// parallel (the writer itself is sequential): a save pays once for the estimate of every node
// whose attributes the file stores (version 3: the sparse nodes').
class NodeSplatBatches {
public:
    // Only the nodes whose attributes `layout` stores are estimated.
    NodeSplatBatches(const Hierarchy& hierarchy, const omh::RecordLayout& layout)
        : m_hierarchy(hierarchy), m_layout(layout) {}

    // Nodes are asked for in order: level by level, each level from index 0.
    const NodeSplats& of(int level, std::size_t index) {
        if (level != m_level || index >= m_batchEnd) {
            fill(level, index);
        }
        return m_batch[index - m_batchBegin];
    }

private:
    void fill(int level, std::size_t begin) {
        const std::size_t nodes = m_hierarchy.nodeCount(level);
        // Batches of about kBatchPoints held points keep memory bounded. Over a cloud in a
        // scratch file, a batch also covers at most an eighth of the budget's worth of its
        // points: the pages it reads stay mapped until the check between batches.
        const SortedCloud& cloud = m_hierarchy.cloud();
        cloud.keepWithinBudget(); // what the previous batch read may go first
        const std::uint64_t maxCovered =
            cloud.fileBacked() ? cloud.residentBudget() / 8 / pointBytes(cloud.attributes())
                               : UINT64_MAX;
        const std::size_t coveredBegin = m_hierarchy.node(level, begin).coveredBegin;
        const auto coveredEnd = [&](std::size_t i) { // of nodes [begin, i]
            const OctreeNode& node = m_hierarchy.node(level, i);
            return std::size_t{node.coveredBegin} + node.coveredCount;
        };
        std::size_t end = begin, points = 0;
        while (end < nodes && (end == begin || (points < kBatchPoints &&
                                                coveredEnd(end) - coveredBegin <= maxCovered))) {
            points += m_hierarchy.node(level, end).pointCount;
            ++end;
        }
        m_level = level;
        m_batchBegin = begin;
        m_batchEnd = end;
        readAhead(coveredBegin, coveredEnd(end - 1), points);
        m_batch.resize(end - begin);
        tbb::parallel_for(begin, end, [&](std::size_t i) {
            const OctreeNode& node = m_hierarchy.node(level, i);
            if (omh::storesSplats(m_layout, node.pointCount)) {
                m_hierarchy.nodeSplats(node, m_batch[i - begin], m_scratch.local());
            }
            cloud.keepWithinBudget(); // faults may outrun the governor's thread
        });
    }

    // A cloud in a scratch file (beyond the memory budget) is read through page faults, one
    // page each (no fault-around there): where the batch's held points are dense in what its
    // nodes cover (leaves, and parents down to a pick every few pages), the covered range is
    // read ahead in bulk first, so the faults find the page cache. Sparse top levels are left
    // to their faults: reading everything they cover would cost more.
    void readAhead(std::size_t coveredBegin, std::size_t coveredEnd, std::size_t heldPoints) const {
        if (heldPoints * kDenseStridePoints >= coveredEnd - coveredBegin) {
            m_hierarchy.cloud().willRead(coveredBegin, coveredEnd); // no-op unless file-backed
        }
    }

    // At most this many covered points per held one for a read-ahead (a pick every two pages
    // of 12-byte positions).
    static constexpr std::size_t kDenseStridePoints = 680;
    static constexpr std::size_t kBatchPoints = std::size_t{1} << 20;
    const Hierarchy& m_hierarchy;
    omh::RecordLayout m_layout;
    tbb::enumerable_thread_specific<SplatScratch> m_scratch;
    std::vector<NodeSplats> m_batch;
    int m_level = -1;
    std::size_t m_batchBegin = 0;
    std::size_t m_batchEnd = 0;
};

} // namespace

omh::BuildInfo omhBuildInfo(const BuildOptions& options, const BuildStatistics& statistics) {
    omh::BuildInfo build;
    build.maxLevel = options.maxLevel;
    build.ratio = options.ratio;
    build.collapse = options.collapse;
    build.inputPoints = statistics.inputPoints;
    build.droppedPoints = statistics.droppedPoints;
    build.collapsedLeaves = statistics.collapsedLeaves;
    return build;
}

namespace {

// Copies the .omh a paged hierarchy reads its points from into `out` and commits it (a
// temporary file, then rename: a failure leaves the old target untouched). The source is read
// through its own descriptor, so copying a file onto itself replaces it while the pager keeps
// reading the old one.
void copyPagedSource(AtomicFileWriter& out, const std::string& source) {
    FileStream in(source);
    std::vector<std::uint8_t> buffer(std::size_t{4} << 20);
    const std::uint64_t size = in.size();
    for (std::uint64_t done = 0; done < size;) {
        const std::size_t count =
            static_cast<std::size_t>(std::min<std::uint64_t>(buffer.size(), size - done));
        in.readExact(buffer.data(), count, "the saved hierarchy it was opened from");
        out.write(buffer.data(), count);
        done += count;
    }
    out.commit();
}

// Levels [0, levels) from the gathered copy of their points, each at its offset in the file
// (already extended past them), filling in their payload checksums.
void writeTopLevelsFromCopy(AtomicFileWriter& file, const Hierarchy& hierarchy,
                            const TopLevelPoints& top, const omh::RecordLayout& layout,
                            std::vector<omh::LevelEntry>& entries, int levels,
                            const std::function<void(int level)>& afterLevel) {
    tbb::enumerable_thread_specific<SplatScratch> scratch;
    for (int level = 0; level < levels; ++level) {
        omh::LevelEntry& entry = entries[static_cast<std::size_t>(level)];
        OmhRecordSink sink(file, top.cloud(), layout, entry.payloadOffset);
        std::vector<OctreeNode> nodes(entry.nodes);
        std::vector<NodeSplats> levelSplats(entry.nodes);
        tbb::parallel_for(std::size_t{0}, entry.nodes, [&](std::size_t i) {
            nodes[i] = top.node(level, i);
            const OctreeNode& node = hierarchy.node(level, i);
            if (!omh::storesSplats(layout, node.pointCount)) {
                return; // the reader estimates them
            }
            if (node.pointCount < kMinPointsPerSplatEstimate) {
                // Borrows its shape from its covered range in the source: read in place.
                hierarchy.nodeSplats(node, levelSplats[i], scratch.local());
            } else {
                estimateNodeSplats(top.cloud(), nodes[i], SparseSplatRegion{},
                                   hierarchy.estimatesNormals(), levelSplats[i], scratch.local());
            }
        });
        for (std::size_t i = 0; i < entry.nodes; ++i) {
            sink.addNode(nodes[i], levelSplats[i]);
        }
        entry.payloadChecksum = sink.finishSection();
        if (afterLevel) {
            afterLevel(level);
        }
    }
}

} // namespace

OmhSaveReport writeOmh(const std::string& path, const Hierarchy& hierarchy,
                       const omh::BuildInfo& build, const OmhWriteOptions& options) {
    AtomicFileWriter file(path);
    return writeOmh(file, hierarchy, build, options);
}

OmhSaveReport writeOmh(AtomicFileWriter& file, const Hierarchy& hierarchy,
                       const omh::BuildInfo& build, const OmhWriteOptions& options) {
    const auto fail = [&](const std::string& what) {
        throw OutputError(file.targetPath() + ": " + what);
    };
    if (!hierarchy.publishedCut().complete) {
        fail("the hierarchy is not complete; only a finished build can be saved");
    }
    if (build.maxLevel != hierarchy.maxLevel()) {
        fail("the build info says depth " + std::to_string(build.maxLevel) +
             ", the hierarchy has depth " + std::to_string(hierarchy.maxLevel()));
    }
    if (const NodeResidency* paged = hierarchy.residency()) {
        // Its points were never all in memory: they are in the .omh it was opened from, and
        // loading a .omh and saving it again gives the same bytes, so the file is the save.
        copyPagedSource(file, paged->backingFile());
        return {};
    }
    const SortedCloud& cloud = hierarchy.cloud();
    omh::Header header;
    header.build = build;
    header.attributes = cloud.attributes();
    header.estimatedNormals = hierarchy.estimatesNormals();
    // Uniform columns go into the header once instead of into every record.
    header.uniformColumns = omhUniformColumns(cloud);
    if ((header.uniformColumns & omh::kUniformIntensityBit) != 0) {
        header.uniformIntensity = cloud.intensities()[0];
    }
    if ((header.uniformColumns & omh::kUniformLasBit) != 0) {
        header.uniformLasRecord.assign(cloud.lasRecord(0),
                                       cloud.lasRecord(0) + header.attributes.lasBytes());
    }
    if (options.formatVersion < 2 || options.formatVersion > omh::kVersion) {
        fail("cannot write .omh format version " + std::to_string(options.formatVersion) +
             " (version 2 to " + std::to_string(omh::kVersion) + ")");
    }
    header.version = options.formatVersion;
    const omh::RecordLayout layout = omh::RecordLayout::of(
        header.attributes, header.estimatedNormals, header.uniformColumns, header.version);
    header.recordBytes = layout.bytes;
    header.cube = cloud.cube();
    header.sourceOffset = cloud.sourceOffset();
    const int levels = hierarchy.maxLevel() + 1;
    header.setLevelCount(static_cast<std::size_t>(levels));
    for (int level = 0; level < levels; ++level) {
        omh::LevelEntry& entry = header.levels[static_cast<std::size_t>(level)];
        entry.nodes = hierarchy.nodeCount(level);
        for (std::size_t i = 0; i < entry.nodes; ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            entry.leaves += node.isLeaf() ? 1 : 0;
            entry.points += node.pointCount;
            if (!layout.splats && omh::storesSplats(node.pointCount)) {
                entry.sparsePoints += node.pointCount;
            }
        }
        header.totalNodes += entry.nodes;
        header.totalPoints += entry.points;
    }
    if (header.levels[0].nodes != 1) {
        fail("the hierarchy has " + std::to_string(header.levels[0].nodes) +
             " nodes at level 0, expected the root alone");
    }
    omh::assignOffsets(header);

    const auto headerBytes = omh::encodeHeader(header);
    file.write(headerBytes.data(), headerBytes.size());
    // The level table holds the sections' checksums, known once they are written: it is
    // written now as a placeholder and overwritten before the file is renamed into place.
    const std::vector<std::uint8_t> placeholder(
        omh::encodeLevelTable(header.levels, header.version).size(), 0);
    file.write(placeholder.data(), placeholder.size());
    // Version 4: the deepest level's columns (streamed during the build, or written by the
    // sweep) lie between the level table and the node table, from the next 4096-byte
    // boundary; the padding before them is zeros.
    if (header.version >= omh::kFirstVersionWithDeepestColumns) {
        const std::vector<std::uint8_t> padding(header.columnsOffset() - header.levelTableEnd(), 0);
        file.write(padding.data(), padding.size());
    }
    file.extendTo(header.nodeTableOffset());

    std::vector<std::uint8_t> records;
    std::uint64_t firstPoint = 0;
    for (int level = 0; level < levels; ++level) {
        omh::LevelEntry& entry = header.levels[static_cast<std::size_t>(level)];
        records.assign(entry.nodes * omh::kNodeRecordBytes, 0);
        for (std::size_t i = 0; i < entry.nodes; ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            std::uint8_t* record = records.data() + i * omh::kNodeRecordBytes;
            store(record + omh::node::kCode, node.code);
            store(record + omh::node::kFirstPoint, firstPoint);
            store(record + omh::node::kPointCount, std::uint64_t{node.pointCount});
            store(record + omh::node::kSplatScale, node.splatScale);
            store(record + omh::node::kChildMask, childMask(hierarchy, level, node));
            store(record + omh::node::kFlags, node.flags);
            firstPoint += node.pointCount;
        }
        entry.nodeChecksum = [&] {
            oms::PayloadChecksum checksum;
            checksum.update(records.data(), records.size());
            return checksum.digest();
        }();
        file.write(records.data(), records.size());
    }

    // The top levels (whose nodes cover more than a batch) a level at a time; their points are
    // few. The rest in one sweep over the cloud, each level at its offset in the file.
    // Over a scratch file: at most an eighth of the budget's worth of points, and on a big
    // budget up to a 32nd of it, so fewer levels are left above the sweep while the batch's
    // splat attributes (6 bytes a point, held in memory beside the budget's file pages) stay a
    // small part of the 256 MiB allowed over it.
    const std::uint64_t budgetPoints =
        cloud.fileBacked() ? cloud.residentBudget() / pointBytes(cloud.attributes()) : 0;
    const std::uint64_t defaultBatch =
        cloud.fileBacked()
            ? std::max(std::clamp<std::uint64_t>(budgetPoints / 8, 1, kSweepBatchPoints),
                       std::min(budgetPoints / 32, kFileBackedSweepBatchPoints))
            : kInMemorySweepBatchPoints;
    std::uint64_t sweepBatch =
        options.sweepBatchPoints > 0 ? options.sweepBatchPoints : defaultBatch;
    const SubtreePoints subtrees = subtreeHeldPoints(hierarchy);
    int firstSweptLevel = omhSweepFirstLevel(subtrees, sweepBatch);
    // Over a scratch file, the top levels' points are copied out as the sweep reads the file,
    // and the top levels are written after it, at their offsets. Read in place instead, they
    // touch points spread over the whole file, and each touch maps a page-cache folio of up to
    // 2 MiB, faster than the governor drops them: a billion points held 1.9-2.5 GB for moments
    // under 1G, 2.5 GB under 256M. The copy is held beside the budget, so where it would take
    // more than a quarter of it, bigger batches leave fewer levels above the sweep, up to
    // batches whose splat attributes (6 bytes a point, two batches in flight) take a quarter
    // of the budget: a billion points under 256M copy 230 MB instead of 1.1 GB.
    const bool gather = options.gatherTopLevels && cloud.fileBacked();
    if (gather && options.sweepBatchPoints == 0) {
        const std::uint64_t quarter = cloud.residentBudget() / 4;
        const std::uint64_t largestBatch = std::max(sweepBatch, quarter / 12);
        while (firstSweptLevel > 0 && sweepBatch < largestBatch &&
               TopLevelPoints::bytesFor(hierarchy, firstSweptLevel) > quarter) {
            sweepBatch = std::min(sweepBatch * 2, largestBatch);
            firstSweptLevel = omhSweepFirstLevel(subtrees, sweepBatch);
        }
    }
    const std::unique_ptr<TopLevelPoints> top =
        gather && firstSweptLevel > 0 ? TopLevelPoints::plan(hierarchy, firstSweptLevel) : nullptr;
    const std::uint64_t payloadEnd = header.footerOffset();
    std::optional<OmhColumnSink> deepestColumns;
    if (header.columnar(header.levels.back())) {
        deepestColumns.emplace(file, hierarchy, header, levels - 1, options.streamedColumns);
    }
    OmhColumnSink* const columns = deepestColumns ? &*deepestColumns : nullptr;
    if (top) {
        file.extendTo(payloadEnd);
        writeOmhLevelsInOneSweep(
            file, hierarchy, layout, header.levels, subtrees, firstSweptLevel, sweepBatch,
            options.afterLevel, [&](std::uint64_t readEnd) { top->copyUpTo(readEnd); }, columns);
        top->finish();
        writeTopLevelsFromCopy(file, hierarchy, *top, layout, header.levels, firstSweptLevel,
                               options.afterLevel);
    } else {
        // The top levels a level at a time, appended; their points are few.
        OmhRecordSink sink(file, cloud, layout);
        NodeSplatBatches splats(hierarchy, layout);
        for (int level = 0; level < firstSweptLevel; ++level) {
            omh::LevelEntry& entry = header.levels[static_cast<std::size_t>(level)];
            for (std::size_t i = 0; i < entry.nodes; ++i) {
                sink.addNode(hierarchy.node(level, i), splats.of(level, i));
            }
            entry.payloadChecksum = sink.finishSection();
            if (options.afterLevel) {
                options.afterLevel(level);
            }
        }
        file.extendTo(payloadEnd);
        writeOmhLevelsInOneSweep(file, hierarchy, layout, header.levels, subtrees, firstSweptLevel,
                                 sweepBatch, options.afterLevel, nullptr, columns);
    }

    const auto footerBytes = omh::encodeFooter(header.totalNodes, header.totalPoints);
    file.write(footerBytes.data(), footerBytes.size());
    const std::vector<std::uint8_t> levelTable =
        omh::encodeLevelTable(header.levels, header.version);
    file.writeAt(header.levelTableOffset(), levelTable.data(), levelTable.size());
    if (options.streamedColumns != nullptr) {
        // A stream sized for more points than the level holds left more file than it needs.
        file.truncateTo(file.bytesWritten());
    }
    file.commit();
    OmhSaveReport report;
    if (deepestColumns && deepestColumns->usesStreamed()) {
        const omh::LevelEntry& deepest = header.levels.back();
        for (const omh::Column& column : header.columns()) {
            report.streamedBytesUsed += deepest.points * column.bytes;
        }
    }
    return report;
}

} // namespace omicron
