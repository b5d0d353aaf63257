// Checker of the Oblique Hierarchy Cut invariants 1.1-1.5 and of every node it reaches.
//
// It walks the cut and the hierarchy as they are and reports the first violation as text
// naming the invariant; it trusts nothing the builder computed (the per-level statistics, the
// builder's counters). Cost O(nodes + points held), so the builder runs it after every fix
// pass only when BuildOptions::checkInvariants is on (tests, and the OMICRON_CHECK_INVARIANTS
// debug build).
#pragma once

#include "build/build_options.hpp"
#include "build/hierarchy.hpp"
#include "build/oblique_cut.hpp"

#include <cstdint>
#include <string>

namespace omicron {

struct CutCheckContext {
    double ratio = 0.2;
    LeafCollapse collapse = LeafCollapse::Off;
    std::uint64_t insertedPoints = 0; // the cloud prefix [0, insertedPoints) was concatenated
    bool requireCompleteFix = false;  // right after a complete fix: every level fixed with m_C
};

// Checks, with m_C = cut.delimiter():
//  1.1 m_C is a code at maxLevel;
//  1.2 L_l holds roots (nodes or placeholders) of level l only;
//  1.3 subtrees are disjoint: each node is reached from exactly one root, and every node of
//      the hierarchy is reached from some root (none lost by a duplicate merge);
//  1.4 every L_l is strictly ascending;
//  1.5 per level: every root of L_l (l >= 1) has a parent with span > fixedThrough(l), and
//      the roots' covered input ranges tile [0, insertedPoints) in span order: every inserted
//      leaf is inside the cut, so every node with span <= the fixed delimiter exists;
// and node/child consistency: levels, Morton order of each level, children contiguous and
// below their parent, covered ranges tiling the parent's and matching the codes, leaves
// holding their range (or their sample under paper collapse), samples of the right size,
// strictly ascending and drawn from the children's points, splat scales.
// Returns an empty string when everything holds.
std::string checkCutInvariants(const ObliqueCut& cut, const Hierarchy& hierarchy,
                               const CutCheckContext& context);

} // namespace omicron
