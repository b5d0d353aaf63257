// The paper's front insertion delay, measured where it ends: for every leaf the builder
// concatenates to the cut (an entry of the Hierarchy's insertion log, stamped with when it was
// published), the time until the first frame that draws its points. A leaf counts as drawn
// when a drawn node covers its input: its own node, or an ancestor whose sample stands for it
// when the front pruned the leaf before it was uploaded. Leaves published before the hierarchy
// was attached to the view are not measured (the view could not have drawn them earlier).
// Render thread only; no GL, so it is testable alone.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace omicron {

class Hierarchy;

class FirstDrawTracker {
public:
    using Clock = std::chrono::steady_clock;

    // A node's covered input range in the SortedCloud: [begin, begin + count).
    struct CoveredRange {
        std::uint32_t begin = 0;
        std::uint32_t count = 0;
    };

    // What take() returns: leaves first drawn since the last take, and their delays.
    struct Delays {
        std::size_t leaves = 0;
        double medianMs = 0.0;
        double maxMs = 0.0;
    };

    // A new hierarchy (or none) attached at `attachedAt`: forgets every leaf.
    void reset(Clock::time_point attachedAt);

    // A frame drew the nodes covering `drawn` (ascending and disjoint: the front's span order)
    // at `now`. Leaves they cover that were not drawn before get their delay. Cost: new log
    // entries, plus a binary search per drawn range that meets a leaf not drawn yet; nothing
    // once every leaf has been drawn.
    void markDrawn(const Hierarchy& hierarchy, std::span<const CoveredRange> drawn,
                   Clock::time_point now);

    // Leaves first drawn since the last call, with the median and maximum delay; clears them.
    Delays take();

    // Leaves logged (since the attach) that no frame has drawn yet.
    std::size_t leavesWaiting() const;

private:
    // Log indices [first, second) of leaves not drawn yet, ascending and disjoint.
    using Interval = std::pair<std::size_t, std::size_t>;

    void takeNewLeaves(const Hierarchy& hierarchy);
    void record(const Hierarchy& hierarchy, std::size_t first, std::size_t last,
                Clock::time_point now);

    Clock::time_point m_attachedAt{};
    std::size_t m_logTaken = 0; // insertion log entries looked at so far
    std::vector<Interval> m_waiting;
    std::vector<Interval> m_scratch;
    std::vector<double> m_delaysMs; // since the last take()
};

} // namespace omicron
