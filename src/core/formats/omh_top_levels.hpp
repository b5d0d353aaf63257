// The points the top levels of a .omh hold, gathered in one sequential pass over a cloud that
// lives in a scratch file (beyond the memory budget).
//
// The top levels are written a level at a time (their subtrees are too large for the sweep's
// batches, omh_payload_sweep.hpp), and every one of them holds a sample spread over the whole
// cloud: read in place, each sparse level costs a page fault (a synchronous 4 KiB read) per
// held point and each dense one a read of the whole scratch file. Their held points together
// are few (a fraction of a percent of the cloud): here they are copied, in Morton order, into a
// small cloud in memory while the scratch file is read once front to back, and the top levels
// are estimated and written from that copy. Same points, same order, same splat estimates, so
// the file's bytes do not change.
#pragma once

#include "build/hierarchy.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace omicron {

class TopLevelPoints {
public:
    // The held points of levels [0, levels) of `hierarchy` (complete, over a file-backed
    // cloud, read a window of an eighth of its budget at a time), or nullptr when they would
    // take more than `maxBytes` in memory (then read them in place).
    static std::unique_ptr<TopLevelPoints> gather(const Hierarchy& hierarchy, int levels,
                                                  std::uint64_t maxBytes);

    // The gathered points, in the source cloud's (Morton) order.
    const SortedCloud& cloud() const { return *m_cloud; }

    // Node `index` of `level` (< levels) holding the same points in cloud(): its code and
    // count as in the hierarchy, its held points renumbered.
    OctreeNode node(int level, std::size_t index) const;

private:
    explicit TopLevelPoints(const Hierarchy& hierarchy) : m_hierarchy(hierarchy) {}

    const Hierarchy& m_hierarchy;
    std::shared_ptr<SortedCloud> m_cloud;
    // Per level: every node's held points as indices into m_cloud, node after node, and
    // where each node's start.
    std::vector<std::vector<std::uint32_t>> m_held;
    std::vector<std::vector<std::uint64_t>> m_firstHeld;
};

} // namespace omicron
