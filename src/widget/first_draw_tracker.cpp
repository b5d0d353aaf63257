#include "first_draw_tracker.hpp"

#include "build/hierarchy.hpp"

#include <algorithm>

namespace omicron {

namespace {

// First log index in [low, high) whose leaf starts at or after `cloudIndex` (the log is in
// span order, so its covered ranges ascend).
std::size_t firstLeafFrom(const Hierarchy& hierarchy, std::size_t low, std::size_t high,
                          std::uint64_t cloudIndex) {
    while (low < high) {
        const std::size_t mid = low + (high - low) / 2;
        if (hierarchy.insertion(mid).coveredBegin < cloudIndex) {
            low = mid + 1;
        } else {
            high = mid;
        }
    }
    return low;
}

} // namespace

void FirstDrawTracker::reset(Clock::time_point attachedAt) {
    m_attachedAt = attachedAt;
    m_logTaken = 0;
    m_waiting.clear();
    m_delaysMs.clear();
}

void FirstDrawTracker::takeNewLeaves(const Hierarchy& hierarchy) {
    const std::size_t count = hierarchy.insertionCount();
    for (std::size_t i = m_logTaken; i < count; ++i) {
        // Publication times ascend along the log: the skipped entries are a prefix.
        if (hierarchy.insertion(i).publishedAt < m_attachedAt) {
            continue;
        }
        if (!m_waiting.empty() && m_waiting.back().second == i) {
            m_waiting.back().second = count;
        } else {
            m_waiting.emplace_back(i, count);
        }
        break;
    }
    m_logTaken = count;
}

void FirstDrawTracker::record(const Hierarchy& hierarchy, std::size_t first, std::size_t last,
                              Clock::time_point now) {
    for (std::size_t i = first; i < last; ++i) {
        m_delaysMs.push_back(
            std::chrono::duration<double, std::milli>(now - hierarchy.insertion(i).publishedAt)
                .count());
    }
}

void FirstDrawTracker::markDrawn(const Hierarchy& hierarchy, std::span<const CoveredRange> drawn,
                                 Clock::time_point now) {
    takeNewLeaves(hierarchy);
    if (m_waiting.empty()) {
        return;
    }
    // One merge of two ascending sequences: drawn ranges (cloud indices) against waiting
    // intervals (log indices, compared through their leaves' covered ranges). A node's range
    // is a union of whole leaves, so the bounds found below never split a leaf.
    m_scratch.clear();
    std::size_t next = 0; // next waiting interval to load
    Interval current{0, 0};
    const auto load = [&] {
        current = next < m_waiting.size() ? m_waiting[next++] : Interval{0, 0};
        return current.first < current.second;
    };
    bool have = load();
    for (const CoveredRange& range : drawn) {
        const std::uint64_t begin = range.begin;
        const std::uint64_t end = begin + range.count;
        while (have) {
            const CutInsertion& firstLeaf = hierarchy.insertion(current.first);
            const CutInsertion& lastLeaf = hierarchy.insertion(current.second - 1);
            if (end <= firstLeaf.coveredBegin) {
                break; // the range lies before this interval: next range
            }
            if (begin >= std::uint64_t{lastLeaf.coveredBegin} + lastLeaf.coveredCount) {
                m_scratch.push_back(current); // nothing of it drawn by this range
                have = load();
                continue;
            }
            const std::size_t from = firstLeafFrom(hierarchy, current.first, current.second, begin);
            const std::size_t to = firstLeafFrom(hierarchy, from, current.second, end);
            if (from > current.first) {
                m_scratch.emplace_back(current.first, from);
            }
            record(hierarchy, from, to, now);
            current.first = to;
            if (to < current.second) {
                break; // the range ends inside the interval
            }
            have = load(); // the range may go on into the next interval
        }
        if (!have) {
            break;
        }
    }
    if (have) {
        m_scratch.push_back(current);
    }
    while (next < m_waiting.size()) {
        m_scratch.push_back(m_waiting[next++]);
    }
    m_waiting.swap(m_scratch);
}

FirstDrawTracker::Delays FirstDrawTracker::take() {
    Delays delays;
    delays.leaves = m_delaysMs.size();
    if (delays.leaves > 0) {
        const auto middle = m_delaysMs.begin() + static_cast<std::ptrdiff_t>(delays.leaves / 2);
        std::nth_element(m_delaysMs.begin(), middle, m_delaysMs.end());
        delays.medianMs = *middle;
        delays.maxMs = *std::max_element(m_delaysMs.begin(), m_delaysMs.end());
        m_delaysMs.clear();
    }
    return delays;
}

std::size_t FirstDrawTracker::leavesWaiting() const {
    std::size_t waiting = 0;
    for (const Interval& interval : m_waiting) {
        waiting += interval.second - interval.first;
    }
    return waiting;
}

} // namespace omicron
