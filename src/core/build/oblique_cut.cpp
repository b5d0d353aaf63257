#include "build/oblique_cut.hpp"

#include <algorithm>
#include <cassert>

namespace omicron {

ObliqueCut::ObliqueCut(int maxLevel)
    : m_maxLevel(maxLevel), m_lists(static_cast<std::size_t>(maxLevel) + 1),
      m_fixedThrough(static_cast<std::size_t>(maxLevel) + 1, 0) {
    assert(maxLevel >= 1 && maxLevel <= morton::kMaxLevel);
}

std::span<const CutRoot> ObliqueCut::roots(int level) const {
    const RootList& list = m_lists[level];
    return std::span<const CutRoot>(list.entries).subspan(list.head);
}

std::uint32_t ObliqueCut::addPlaceholder(const Placeholder& placeholder) {
    assert(morton::level(placeholder.leafCode) < m_maxLevel);
    m_placeholders.push_back(placeholder);
    return static_cast<std::uint32_t>(m_placeholders.size() - 1);
}

void ObliqueCut::concatenate(std::span<const CutRoot> leaves) {
    assert(!m_closed);
    if (leaves.empty()) {
        return;
    }
#ifndef NDEBUG
    morton::Code previous = m_delimiter;
    for (const CutRoot& leaf : leaves) {
        assert(morton::level(leaf.code) == m_maxLevel);
        assert(leaf.code > previous);
        assert(!leaf.placeholder ||
               leaf.code == morton::span(m_placeholders[leaf.index].leafCode, m_maxLevel));
        previous = leaf.code;
    }
#endif
    std::vector<CutRoot>& list = m_lists[m_maxLevel].entries;
    list.insert(list.end(), leaves.begin(), leaves.end());
    m_delimiter = leaves.back().code;
}

void ObliqueCut::close() {
    m_closed = true;
    m_delimiter = morton::span(morton::kRoot, m_maxLevel);
}

std::span<const CutRoot> ObliqueCut::pendingRoots(int level) const {
    assert(level >= 1 && level <= m_maxLevel);
    const std::span<const CutRoot> all = roots(level);
    if (m_delimiter == 0) {
        return all.first(0);
    }
    // Parents' spans ascend along the list, so the qualifying roots are a prefix.
    const auto end = std::partition_point(all.begin(), all.end(), [&](const CutRoot& root) {
        return morton::span(root.code >> 3, m_maxLevel) <= m_delimiter;
    });
    return all.first(static_cast<std::size_t>(end - all.begin()));
}

void ObliqueCut::completeLevel(int level, std::span<const CutRoot> parents) {
    RootList& list = m_lists[level];
    const std::size_t pending = pendingRoots(level).size();
    assert(parents.size() <= pending);
    list.head += pending;
    // Reclaim the consumed prefix once it dominates, so the lists stay proportional to L_C.
    if (list.head > 1024 && list.head * 2 > list.entries.size()) {
        list.entries.erase(list.entries.begin(),
                           list.entries.begin() + static_cast<std::ptrdiff_t>(list.head));
        list.head = 0;
    }
    std::vector<CutRoot>& above = m_lists[level - 1].entries;
    for (const CutRoot& parent : parents) {
        assert(morton::level(parent.code) == level - 1);
        assert(above.empty() || above.back().code < parent.code);
        above.push_back(parent);
    }
    m_fixedThrough[level] = m_delimiter;
}

void fix(ObliqueCut& cut, ParentFactory& factory) {
    std::vector<CutRoot> parents;
    for (int level = cut.maxLevel(); level >= 1; --level) {
        parents.clear();
        forEachSiblingGroup(cut.pendingRoots(level), [&](std::span<const CutRoot> siblings) {
            parents.push_back(factory.makeParent(level - 1, siblings));
        });
        cut.completeLevel(level, parents);
    }
}

} // namespace omicron
