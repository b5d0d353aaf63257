#include "front/front_substitution.hpp"

#include <cassert>

namespace omicron {

FrontSubstitution::FrontSubstitution(int maxLevel)
    : m_lists(static_cast<std::size_t>(maxLevel) + 1) {}

void FrontSubstitution::add(morton::Code code, std::uint32_t logIndex, std::uint64_t evaluation) {
    List& list = m_lists[morton::level(code)];
    assert(list.leaves.empty() || list.leaves.back().code < code);
    list.leaves.push_back({code, logIndex, 0, evaluation, 0});
}

void FrontSubstitution::updateReady(const Hierarchy& hierarchy, const PublishedCut& cut,
                                    std::span<const std::size_t> nodeCounts,
                                    std::uint64_t evaluation) {
    for (std::size_t level = 0; level < m_lists.size(); ++level) {
        List& list = m_lists[level];
        const std::size_t published = nodeCounts[level];
        while (list.readyEnd < list.leaves.size()) {
            Leaf& leaf = list.leaves[list.readyEnd];
            if (!Hierarchy::isSettled(leaf.code, cut, hierarchy.maxLevel())) {
                break; // settled nodes are a Morton prefix of their level: none further is
            }
            // The leaf's node: the level is in Morton order and so is the list, so the search
            // only moves forward (past the level's inner nodes): O(1) amortised per leaf.
            while (list.nodeCursor < published &&
                   hierarchy.node(static_cast<int>(level), list.nodeCursor).code < leaf.code) {
                ++list.nodeCursor;
            }
            if (list.nodeCursor == published) {
                break; // a collapsed leaf fix has not made yet
            }
            assert(hierarchy.node(static_cast<int>(level), list.nodeCursor).code == leaf.code);
            leaf.nodeIndex = static_cast<std::uint32_t>(list.nodeCursor);
            leaf.readyEval = evaluation;
            ++list.readyEnd;
        }
    }
}

int FrontSubstitution::chooseLevel() {
    int chosen = -1;
    for (int level = 0; level < static_cast<int>(m_lists.size()); ++level) {
        const List& list = m_lists[level];
        if (readyCount(level) == 0) {
            continue;
        }
        if (chosen < 0) {
            chosen = level;
            continue;
        }
        const List& best = m_lists[chosen];
        // Longest passed over first; then the paper's rule, most ready leaves.
        if (list.sweepsPassedOver != best.sweepsPassedOver
                ? list.sweepsPassedOver > best.sweepsPassedOver
                : readyCount(level) > readyCount(chosen)) {
            chosen = level;
        }
    }
    for (int level = 0; level < static_cast<int>(m_lists.size()); ++level) {
        List& list = m_lists[level];
        if (level == chosen) {
            list.sweepsPassedOver = 0;
            compact(list);
        } else if (readyCount(level) > 0) {
            ++list.sweepsPassedOver;
        }
    }
    return chosen;
}

// Drops substituted leaves once they are most of the list, so memory follows what waits.
void FrontSubstitution::compact(List& list) {
    if (list.head < 4096 || list.head < list.leaves.size() / 2) {
        return;
    }
    list.leaves.erase(list.leaves.begin(),
                      list.leaves.begin() + static_cast<std::ptrdiff_t>(list.head));
    list.readyEnd -= list.head;
    list.head = 0;
}

std::span<const FrontSubstitution::Leaf> FrontSubstitution::waiting(int level) const {
    const List& list = m_lists[level];
    return std::span<const Leaf>(list.leaves).subspan(list.head);
}

std::size_t FrontSubstitution::waitingCount() const {
    std::size_t count = 0;
    for (const List& list : m_lists) {
        count += list.leaves.size() - list.head;
    }
    return count;
}

} // namespace omicron
