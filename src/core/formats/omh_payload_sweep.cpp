#include "formats/omh_payload_sweep.hpp"

#include "formats/background_job.hpp"
#include "formats/omh_record_sink.hpp"
#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <array>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <utility>

namespace omicron {

namespace {

std::uint64_t coveredEnd(const OctreeNode& node) {
    return std::uint64_t{node.coveredBegin} + node.coveredCount;
}

// The writer's side of the sweep: the records of a batch's nodes, level run after level run,
// cut into blocks of about 1 MiB. A pipeline encodes blocks in parallel (TBB shares the cores
// with the estimation of the next batch) and hashes and writes each one, in order, as soon as
// it is encoded: the write (on a tmpfs, the kernel allocating the file's pages under the
// inode's lock, one writer at a time) is the save's serial path, so nothing else waits for it
// and it never waits for a round of encoding. Measured on 24.2 M points: while blocks were
// encoded eight at a time and then written, the writer's thread was busy the whole save and
// the other core a fifth idle. The tokens in flight bound the memory it takes.
class ParallelRecordEncoder {
public:
    ParallelRecordEncoder(const SortedCloud& cloud, const omh::RecordLayout& layout,
                          std::vector<OmhRecordSink>& sinks, int firstLevel)
        : m_cloud(cloud), m_layout(layout), m_sinks(sinks), m_firstLevel(firstLevel),
          m_blockRecords(std::max<std::size_t>(1, kBlockBytes / layout.bytes)) {}

    // Queues the records of every point `node` holds; `node` and `splats` must stay valid
    // until finish().
    void add(int level, const OctreeNode& node, const NodeSplats& splats) {
        m_sinks[static_cast<std::size_t>(level - m_firstLevel)].addSparseSplats(node, splats);
        for (std::uint32_t p = 0; p < node.pointCount;) {
            if (m_blocks.empty() || m_blocks.back().level != level ||
                m_blocks.back().records == m_blockRecords) {
                m_blocks.push_back({level, 0, {}});
            }
            Block& block = m_blocks.back();
            const auto take = static_cast<std::uint32_t>(
                std::min<std::size_t>(m_blockRecords - block.records, node.pointCount - p));
            block.pieces.push_back({&node, &splats, p, p + take});
            block.records += take;
            p += take;
        }
    }

    // Encodes what is queued, in parallel, and writes it in order.
    void finish() {
        const std::size_t buffers = std::min(kTokens, m_blocks.size());
        if (m_buffers.size() < buffers * kBlockBytes) {
            m_buffers = HugePageArray<std::uint8_t>(buffers * kBlockBytes);
        }
        std::size_t next = 0;
        const auto nextBlock = [&](tbb::flow_control& control) -> std::size_t {
            if (next == m_blocks.size()) {
                control.stop();
                return 0;
            }
            return next++;
        };
        const auto encodeBlock = [&](std::size_t i) {
            encode(i);
            return i;
        };
        const auto writeBlock = [&](std::size_t i) {
            write(i);
        };
        // A token holds its buffer from the first stage to the last, and the last stage is
        // serial in order: block i starts only once block i - kTokens is written, so the
        // buffer i % kTokens is free.
        tbb::parallel_pipeline(
            kTokens,
            tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order, nextBlock) &
                tbb::make_filter<std::size_t, std::size_t>(tbb::filter_mode::parallel,
                                                           encodeBlock) &
                tbb::make_filter<std::size_t, void>(tbb::filter_mode::serial_in_order, writeBlock));
        m_blocks.clear();
    }

private:
    void encode(std::size_t i) {
        const Block& block = m_blocks[i];
        std::uint8_t* out = buffer(i);
        for (const Piece& piece : block.pieces) {
            encodeOmhRecords(m_cloud, m_layout, *piece.node, *piece.splats, piece.first, piece.last,
                             out);
            out += std::size_t{piece.last - piece.first} * m_layout.bytes;
        }
        m_cloud.keepWithinBudget(); // as the estimation does, per block
    }

    // Hashes and writes block i through its level's sink (the pipeline's serial stage).
    void write(std::size_t i) {
        m_sinks[static_cast<std::size_t>(m_blocks[i].level - m_firstLevel)].addEncoded(
            buffer(i), m_blocks[i].records * m_layout.bytes);
    }

    // Block i's buffer: the one its token holds (a block is at most kBlockBytes).
    std::uint8_t* buffer(std::size_t i) { return m_buffers.data() + i % kTokens * kBlockBytes; }

    static constexpr std::size_t kBlockBytes = std::size_t{1} << 20;
    static constexpr std::size_t kTokens = 8; // 8 MiB of records at most
    struct Piece {
        const OctreeNode* node;
        const NodeSplats* splats;
        std::uint32_t first; // held points [first, last) of the node
        std::uint32_t last;
    };
    struct Block {
        int level = 0;
        std::size_t records = 0;
        std::vector<Piece> pieces;
    };
    const SortedCloud& m_cloud;
    omh::RecordLayout m_layout;
    std::vector<OmhRecordSink>& m_sinks;
    int m_firstLevel;
    std::size_t m_blockRecords;
    std::vector<Block> m_blocks; // the batch's, in file order per level
    // The tokens' buffers, one after the other. Never zeroed: a block is encoded whole
    // before it is written (resizing a vector zeroed what it grew by, 35 ms of a 24.2 M-point
    // save). On huge pages where they pay off: eight buffers on small pages took about 1,000
    // first touches at the start of the save, 12 ms on the test VM.
    HugePageArray<std::uint8_t> m_buffers;
};

} // namespace

SubtreePoints subtreeHeldPoints(const Hierarchy& hierarchy) {
    const int levelCount = hierarchy.maxLevel() + 1;
    SubtreePoints subtrees(static_cast<std::size_t>(levelCount));
    for (int level = levelCount - 1; level >= 0; --level) {
        std::vector<std::uint64_t>& held = subtrees[static_cast<std::size_t>(level)];
        held.resize(hierarchy.nodeCount(level));
        for (std::size_t i = 0; i < held.size(); ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            held[i] = node.pointCount;
            for (std::uint32_t c = 0; c < node.childCount; ++c) {
                held[i] += subtrees[static_cast<std::size_t>(level) + 1][node.firstChild + c];
            }
        }
    }
    return subtrees;
}

int omhSweepFirstLevel(const SubtreePoints& subtrees, std::uint64_t maxBatchPoints) {
    const int deepest = static_cast<int>(subtrees.size()) - 1;
    for (int level = 0; level < deepest; ++level) {
        const std::vector<std::uint64_t>& held = subtrees[static_cast<std::size_t>(level)];
        if (std::all_of(held.begin(), held.end(),
                        [&](std::uint64_t points) { return points <= maxBatchPoints; })) {
            return level;
        }
    }
    return deepest;
}

void writeOmhLevelsInOneSweep(AtomicFileWriter& file, const Hierarchy& hierarchy,
                              const omh::RecordLayout& layout, std::vector<omh::LevelEntry>& levels,
                              const SubtreePoints& subtrees, int firstLevel,
                              std::uint64_t maxBatchPoints,
                              const std::function<void(int level)>& afterLevel,
                              const std::function<void(std::uint64_t readEnd)>& afterRead,
                              OmhColumnSink* deepestColumns) {
    const SortedCloud& cloud = hierarchy.cloud();
    const int levelCount = hierarchy.maxLevel() + 1;
    std::vector<OmhRecordSink> sinks;
    sinks.reserve(static_cast<std::size_t>(levelCount - firstLevel));
    for (int level = firstLevel; level < levelCount; ++level) {
        sinks.emplace_back(file, cloud, layout,
                           levels[static_cast<std::size_t>(level)].payloadOffset);
    }
    // The next node of each level not yet written. Children are stored in their parents'
    // order, so a batch's nodes at each level follow those of the level above: as many as
    // the batch's nodes there have children.
    std::vector<std::size_t> next(static_cast<std::size_t>(levelCount), 0);
    // Batches in flight: while a writer thread encodes (in parallel), hashes and writes
    // (serially; on a disk mostly waiting for it) one, the calling thread and TBB estimate the
    // splat attributes of the next (parallel, and over a scratch file mostly waiting for its
    // reads). Only the writer touches the sinks and the encoder; both stages only read the
    // hierarchy and the cloud. In memory the estimation may run a second batch ahead: the
    // writer's serial stage (the hash and the kernel's copy) is the longer of the two, and
    // while the calling thread waited for it the other core idled once the writer had encoded
    // its tokens ahead (24.2 M points: an eighth of the save). Over a scratch file two batches
    // (their splats sized to the budget) are all it holds.
    struct Batch {
        std::vector<std::pair<int, std::size_t>> nodes; // (level, index), level by level
        std::vector<NodeSplats> splats;
    };
    const std::size_t slots = cloud.fileBacked() ? 2 : 3;
    std::array<Batch, 3> batches;
    ParallelRecordEncoder encoder(cloud, layout, sinks, firstLevel);
    const int deepest = levelCount - 1;
    const auto write = [&](const Batch& batch) {
        for (std::size_t b = 0; b < batch.nodes.size(); ++b) {
            const auto [level, index] = batch.nodes[b];
            if (deepestColumns != nullptr && level == deepest) {
                deepestColumns->addNode(hierarchy.node(level, index), batch.splats[b]);
            } else {
                encoder.add(level, hierarchy.node(level, index), batch.splats[b]);
            }
        }
        encoder.finish(); // before the batch's splats are reused
    };
    // The writes of the batches before (slots - 1 at most); its destructor waits for them.
    BackgroundJob writing(slots - 1);
    tbb::enumerable_thread_specific<SplatScratch> scratch;

    const std::vector<std::uint64_t>& rootPoints = subtrees[static_cast<std::size_t>(firstLevel)];
    const std::size_t roots = rootPoints.size();
    // The batch of subtrees that starts at `begin` ends before the returned root.
    const auto batchEnd = [&](std::size_t begin) {
        std::size_t end = begin + 1;
        for (std::uint64_t points = rootPoints[begin];
             end < roots && points + rootPoints[end] <= maxBatchPoints; ++end) {
            points += rootPoints[end];
        }
        return end;
    };
    // A built hierarchy's subtrees cover one stretch of the cloud: read it in bulk, on a
    // thread of its own (the kernel submits a read-ahead's reads as it goes, and waits when the
    // device's queue is full), one batch ahead of the estimation. No-op in memory.
    BackgroundJob reading; // the read-ahead in flight; its destructor waits for it
    const auto readAhead = [&](std::size_t begin, std::size_t end) {
        if (!cloud.fileBacked()) {
            return;
        }
        const std::uint64_t from = hierarchy.node(firstLevel, begin).coveredBegin;
        const std::uint64_t to = coveredEnd(hierarchy.node(firstLevel, end - 1));
        reading.start([&cloud, from, to] { cloud.willRead(from, to); });
    };
    std::size_t end = roots > 0 ? batchEnd(0) : 0;
    if (roots > 0) {
        readAhead(0, end);
    }
    for (std::size_t begin = 0, slot = 0; begin < roots; slot = (slot + 1) % slots) {
        cloud.keepWithinBudget(); // what the previous batch read may go first
        // The next batch's stretch is read while this one is estimated and written (a cloud
        // in a scratch file: the disk reads ahead instead of waiting for each batch's faults).
        const std::size_t nextEnd = end < roots ? batchEnd(end) : roots;
        if (end < roots) {
            readAhead(end, nextEnd);
        }
        // The writer is done with this slot: start() below waited for its write.
        Batch& batch = batches[slot];
        batch.nodes.clear();
        std::size_t count = end - begin;
        for (int level = firstLevel; level < levelCount && count > 0; ++level) {
            std::size_t& first = next[static_cast<std::size_t>(level)];
            std::size_t children = 0;
            for (std::size_t i = first; i < first + count; ++i) {
                batch.nodes.emplace_back(level, i);
                children += hierarchy.node(level, i).childCount;
            }
            first += count;
            count = children;
        }
        batch.splats.resize(batch.nodes.size());
        tbb::parallel_for(std::size_t{0}, batch.nodes.size(), [&](std::size_t b) {
            const auto [level, index] = batch.nodes[b];
            const OctreeNode& node = hierarchy.node(level, index);
            if (omh::storesSplats(layout, node.pointCount)) { // else the reader estimates them
                hierarchy.nodeSplats(node, batch.splats[b], scratch.local());
            }
            // Over a scratch-file cloud read ahead, faults find the page cache and map pages
            // faster than the governor's thread, which may wait for a core, can drop them.
            cloud.keepWithinBudget();
        });
        if (afterRead) { // the batch's pages are in memory: the estimation read them
            afterRead(coveredEnd(hierarchy.node(firstLevel, end - 1)));
        }
        // Waits until at most slots - 2 earlier batches are still being written (or throws
        // the error of one), so the slot estimated next is free.
        writing.start([&write, &batch] { write(batch); });
        begin = end;
        end = nextEnd;
    }
    writing.wait();
    for (int level = firstLevel; level < levelCount; ++level) {
        levels[static_cast<std::size_t>(level)].payloadChecksum =
            deepestColumns != nullptr && level == deepest
                ? deepestColumns->finishSection()
                : sinks[static_cast<std::size_t>(level - firstLevel)].finishSection();
        if (afterLevel) {
            afterLevel(level);
        }
    }
}

} // namespace omicron
