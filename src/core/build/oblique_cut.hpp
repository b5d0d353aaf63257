// The Oblique Hierarchy Cut C = (m_C, L_C) of the paper (section "Oblique Hierarchy Cuts").
//
// m_C (delimiter()) is a code at maxLevel; L_C is one list of subtree roots per level, each in
// Morton order. The cut keeps five invariants: (1.1) m_C is at maxLevel; (1.2) L_l holds roots
// of level l; (1.3) the subtrees are disjoint; (1.4) every L_l is in Morton order; (1.5) every
// node N with span(N) <= m_C lies in some subtree. concatenate() appends new maxLevel leaves
// (all > m_C) and moves m_C to the last; it breaks only (1.5), which fix() restores: bottom-up,
// every run of sibling roots in L_l whose parent P has span(P) <= m_C becomes the children of
// a new root P appended to L_{l-1}. Roots whose parent has span > m_C stay: their parents form
// the boundary S.
//
// Nodes of a level are therefore created in Morton order (parents qualify in span order, and
// span order is Morton order within a level), which is what lets Hierarchy store them as an
// append-only sorted array and a parent refer to its children as one contiguous range.
//
// Placeholders stand for leaves shallower than maxLevel (leaf collapse): a leaf X at level
// l < maxLevel enters L_maxLevel as the code span(X), the right-most descendant slot, and rises
// one level per fix step as (code >> 3) until it reaches level l and becomes X. It keeps the
// lists in Morton order without the leaf being inserted out of turn.
//
// fix() is split into level steps (pendingRoots + completeLevel) so that the builder can run
// each level's groups in parallel and stop a pass part way up to take new input (multipass);
// fixedThrough(l) records the delimiter level l was last fixed with. Between level steps the
// cut satisfies 1.1-1.5 with m_C = fixedThrough(1) (and, level by level, every root of L_l has
// a parent with span > fixedThrough(l)); after a complete fix, with m_C = delimiter().
#pragma once

#include "points/morton.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace omicron {

// An entry of L_l: a subtree root (a node of the hierarchy) or a placeholder.
struct CutRoot {
    morton::Code code = 0;
    std::uint32_t index = 0; // the node's index in its level, or the placeholder's id
    bool placeholder = false;
    friend bool operator==(const CutRoot&, const CutRoot&) = default;
};

// What a placeholder stands for: a leaf at a level above maxLevel and the input it covers.
struct Placeholder {
    morton::Code leafCode = 0;
    std::uint32_t coveredBegin = 0;
    std::uint32_t coveredCount = 0;
};

class ObliqueCut {
public:
    explicit ObliqueCut(int maxLevel);

    int maxLevel() const { return m_maxLevel; }
    // True once a leaf was concatenated (before, m_C is undefined and the cut is empty).
    bool hasDelimiter() const { return m_delimiter != 0; }
    morton::Code delimiter() const { return m_delimiter; }
    // True after close(): no input will follow.
    bool closed() const { return m_closed; }
    morton::Code fixedThrough(int level) const { return m_fixedThrough[level]; }

    std::span<const CutRoot> roots(int level) const;
    const Placeholder& placeholder(std::uint32_t id) const { return m_placeholders[id]; }
    std::size_t placeholderCount() const { return m_placeholders.size(); }

    // Registers the leaf a placeholder stands for; returns the id to put in its CutRoot, whose
    // code must be span(leafCode) when concatenated.
    std::uint32_t addPlaceholder(const Placeholder& placeholder);

    // The paper's concatenate: `leaves` at maxLevel (nodes or placeholders), ascending, all
    // greater than delimiter(). Sets delimiter() to the last one.
    void concatenate(std::span<const CutRoot> leaves);

    // Input ended: m_C becomes span(root), the last code at maxLevel, so that the next fix
    // completes the hierarchy (the paper's "S holds only the null node").
    void close();

    // ---- fix, one level step at a time (levels maxLevel down to 1). ----

    // The prefix of L_level that fix moves now: roots whose parent has span <= delimiter().
    std::span<const CutRoot> pendingRoots(int level) const;
    // Replaces pendingRoots(level) by `parents` (the roots they form, ascending, appended to
    // L_{level-1}) and records fixedThrough(level) = delimiter().
    void completeLevel(int level, std::span<const CutRoot> parents);

private:
    struct RootList {
        std::vector<CutRoot> entries;
        std::size_t head = 0; // entries before head were moved into parents
    };

    int m_maxLevel;
    morton::Code m_delimiter = 0;
    bool m_closed = false;
    std::vector<RootList> m_lists;
    std::vector<morton::Code> m_fixedThrough;
    std::vector<Placeholder> m_placeholders;
};

// Creates the root that replaces one sibling group during fix: a new parent node, a leaf that
// a placeholder reached, or the placeholder one level up.
class ParentFactory {
public:
    virtual ~ParentFactory() = default;
    // `siblings`: one or more roots of level parentLevel + 1 sharing a parent, ascending.
    virtual CutRoot makeParent(int parentLevel, std::span<const CutRoot> siblings) = 0;
};

// The paper's fix, sequential: every level from maxLevel up to 1, every group in Morton order.
void fix(ObliqueCut& cut, ParentFactory& factory);

// Calls fn(std::span<const CutRoot>) for each maximal run of `roots` that shares a parent.
template <typename Fn> void forEachSiblingGroup(std::span<const CutRoot> roots, Fn&& fn) {
    std::size_t begin = 0;
    while (begin < roots.size()) {
        const morton::Code parent = roots[begin].code >> 3;
        std::size_t end = begin + 1;
        while (end < roots.size() && (roots[end].code >> 3) == parent) {
            ++end;
        }
        fn(roots.subspan(begin, end - begin));
        begin = end;
    }
}

} // namespace omicron
