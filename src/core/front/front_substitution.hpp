// The front's per-level "to substitute" lists (paper, "Substitution of placeholders" and
// "Choice of substitution level").
//
// Every leaf the builder concatenates enters the front as a placeholder and the list of its
// level, both in span order, so at one level the placeholders in the front and the list are
// in the same order: a sweep over the front that compares each placeholder of the chosen
// level with the head of that level's list substitutes every ready leaf of the level, O(1)
// per placeholder. A leaf is ready once it is published and Hierarchy::isSettled. Settled
// nodes of a level form a prefix in Morton order, so each list keeps a ready cursor that only
// moves forward.
//
// The level of a sweep is the paper's choice, the level with the most ready leaves, with one
// guard the paper lacks: a level that had ready leaves at the start of a sweep and was passed
// over goes first next time (longest wait first), so a level that keeps receiving fewer
// leaves is not starved. A leaf ready at the start of a sweep is therefore substituted within
// as many sweeps as there are levels with ready leaves: at most 2 with this builder (maxLevel
// and, with leaf collapse, maxLevel - 1), within the paper's l_max - 1 for l_max >= 3.
#pragma once

#include "build/hierarchy.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace omicron {

class FrontSubstitution {
public:
    struct Leaf {
        morton::Code code = 0;
        std::uint32_t logIndex = 0;     // its entry in the hierarchy's insertion log
        std::uint32_t nodeIndex = 0;    // index in its level, once ready
        std::uint64_t insertedEval = 0; // evaluation that appended its placeholder
        std::uint64_t readyEval = 0;    // evaluation that first found it ready
    };

    explicit FrontSubstitution(int maxLevel);

    // Registers a leaf whose placeholder was just appended to the front (span order).
    void add(morton::Code code, std::uint32_t logIndex, std::uint64_t evaluation);

    // Moves every level's ready cursor over the leaves now published and settled.
    void updateReady(const Hierarchy& hierarchy, const PublishedCut& cut,
                     std::span<const std::size_t> nodeCounts, std::uint64_t evaluation);

    // Picks the level a new sweep substitutes (-1 when nothing is ready).
    int chooseLevel();

    // True when `code` (a placeholder of `level`) is the head of its list and ready.
    bool headIsReady(int level, morton::Code code) const {
        const List& list = m_lists[level];
        return list.head < list.readyEnd && list.leaves[list.head].code == code;
    }
    // Removes and returns the head of `level` (headIsReady must hold).
    const Leaf& takeHead(int level) { return m_lists[level].leaves[m_lists[level].head++]; }

    std::size_t readyCount(int level) const { return m_lists[level].readyEnd - m_lists[level].head; }
    // The leaves of `level` still waiting, in order (their placeholders are in the front).
    std::span<const Leaf> waiting(int level) const;
    std::size_t waitingCount() const;

private:
    struct List {
        std::vector<Leaf> leaves;
        std::size_t head = 0;         // leaves before head were substituted
        std::size_t readyEnd = 0;     // leaves [head, readyEnd) are ready
        std::size_t nodeCursor = 0;   // where the search for the next ready leaf's node resumes
        std::uint32_t sweepsPassedOver = 0;
    };

    void compact(List& list);

    std::vector<List> m_lists;
};

} // namespace omicron
