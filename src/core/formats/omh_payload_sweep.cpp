#include "formats/omh_payload_sweep.hpp"

#include "formats/omh_record_sink.hpp"

#include <algorithm>
#include <array>
#include <future>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <utility>

namespace omicron {

namespace {

std::uint64_t coveredEnd(const OctreeNode& node) {
    return std::uint64_t{node.coveredBegin} + node.coveredCount;
}

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
                              const std::function<void(int level)>& afterLevel) {
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
    // Two batches in flight: while a writer thread encodes, hashes and writes one (serial,
    // and on a disk mostly waiting for it), the calling thread and TBB estimate the splat
    // attributes of the next (parallel, and over a scratch file mostly waiting for its reads).
    // Only the writer touches the sinks; both stages only read the hierarchy and the cloud.
    struct Batch {
        std::vector<std::pair<int, std::size_t>> nodes; // (level, index), level by level
        std::vector<NodeSplats> splats;
    };
    std::array<Batch, 2> batches;
    const auto write = [&](const Batch& batch) {
        for (std::size_t b = 0; b < batch.nodes.size(); ++b) {
            const auto [level, index] = batch.nodes[b];
            sinks[static_cast<std::size_t>(level - firstLevel)].addNode(
                hierarchy.node(level, index), batch.splats[b]);
        }
    };
    std::future<void> writing; // of the previous batch; its destructor waits for it
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
    // A built hierarchy's subtrees cover one stretch of the cloud: read it in bulk.
    const auto readAhead = [&](std::size_t begin, std::size_t end) {
        cloud.willRead(hierarchy.node(firstLevel, begin).coveredBegin,
                       coveredEnd(hierarchy.node(firstLevel, end - 1)));
    };
    std::size_t end = roots > 0 ? batchEnd(0) : 0;
    if (roots > 0) {
        readAhead(0, end);
    }
    for (std::size_t begin = 0, slot = 0; begin < roots; slot ^= 1) {
        cloud.keepWithinBudget(); // what the previous batch read may go first
        // The next batch's stretch is read while this one is estimated and written (a cloud
        // in a scratch file: the disk reads ahead instead of waiting for each batch's faults).
        const std::size_t nextEnd = end < roots ? batchEnd(end) : roots;
        if (end < roots) {
            readAhead(end, nextEnd);
        }
        Batch& batch = batches[slot]; // the writer is done with it: waited for below
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
            hierarchy.nodeSplats(hierarchy.node(level, index), batch.splats[b], scratch.local());
        });
        if (writing.valid()) {
            writing.get(); // the previous batch is written (or its error is thrown here)
        }
        writing = std::async(std::launch::async, [&write, &batch] { write(batch); });
        begin = end;
        end = nextEnd;
    }
    if (writing.valid()) {
        writing.get();
    }
    for (int level = firstLevel; level < levelCount; ++level) {
        levels[static_cast<std::size_t>(level)].payloadChecksum =
            sinks[static_cast<std::size_t>(level - firstLevel)].finishSection();
        if (afterLevel) {
            afterLevel(level);
        }
    }
}

} // namespace omicron
