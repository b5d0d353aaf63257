// The points the top levels of a .omh hold, gathered while a save sweeps a cloud that lives
// in a scratch file (beyond the memory budget).
//
// The top levels are written a level at a time (their subtrees are too large for the sweep's
// batches, omh_payload_sweep.hpp), and every one of them holds a sample spread over the whole
// cloud: read in place, each sparse level costs a page fault (a synchronous 4 KiB read) per
// held point and each dense one a read of the whole scratch file. Their held points together
// are few (a fraction of a percent of the cloud): here they are copied, in Morton order, into a
// small cloud in memory as the sweep of the deeper levels reads the scratch file front to back
// (each batch's stretch is in memory then), so the file is read once for the whole save, and
// the top levels are estimated and written from that copy afterwards. Same points, same order,
// same splat estimates, so the file's bytes do not change.
#pragma once

#include "build/hierarchy.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace omicron {

class TopLevelPoints {
public:
    // Bytes the copy of levels [0, levels) of `hierarchy` takes at most: their held points
    // (a point held by several levels counts once per level) and their renumbered indices.
    static std::uint64_t bytesFor(const Hierarchy& hierarchy, int levels);

    // Plans the copy of the held points of levels [0, levels) of `hierarchy` (complete, over a
    // file-backed cloud). Copies nothing yet.
    static std::unique_ptr<TopLevelPoints> plan(const Hierarchy& hierarchy, int levels);

    // Copies the planned points below cloud index `end` not copied yet; calls come with
    // growing `end`, typically as each stretch of the source is in memory.
    void copyUpTo(std::uint64_t end);
    // Copies the rest; cloud() is complete afterwards.
    void finish();

    // The gathered points, in the source cloud's (Morton) order.
    const SortedCloud& cloud() const { return *m_cloud; }

    // Node `index` of `level` (< levels) holding the same points in cloud(): its code and
    // count as in the hierarchy, its held points renumbered.
    OctreeNode node(int level, std::size_t index) const;

private:
    explicit TopLevelPoints(const Hierarchy& hierarchy) : m_hierarchy(hierarchy) {}

    const Hierarchy& m_hierarchy;
    std::shared_ptr<SortedCloud> m_cloud;
    // The source indices to copy, ascending, and how many of them are copied.
    std::vector<std::uint32_t> m_points;
    std::size_t m_copied = 0;
    // Per level: every node's held points as indices into m_cloud, node after node, and
    // where each node's start.
    std::vector<std::vector<std::uint32_t>> m_held;
    std::vector<std::vector<std::uint64_t>> m_firstHeld;
};

} // namespace omicron
