// Which points a parent node keeps: a stratified sample in Morton order.
//
// The children's held point lists, concatenated in child order, are one ascending list of
// SortedCloud indices in Morton order; the parent keeps `count` evenly spaced elements of it
// (pick j is element floor((2j + 1) n / 2count)). Morton order makes evenly spaced picks
// spatially spread; the picks are distinct because count <= n; the result depends only on the
// children, never on threads or timing; and it costs O(count), not O(n).
#pragma once

#include "build/octree_node.hpp"

#include <cstdint>
#include <span>

namespace omicron {

// max(1, round(ratio x childrenPoints)), never more than childrenPoints (ratio in (0, 1]).
std::uint32_t sampleSize(std::uint64_t childrenPoints, double ratio);

// Fills `out` (out.size() <= the children's total pointCount, > 0) with the stratified picks
// from the held points of `children` (in ascending code order).
void sampleChildren(std::span<const OctreeNode* const> children, std::span<std::uint32_t> out);

// The same over the SortedCloud range [begin, begin + count) (a paper-collapsed leaf).
void sampleRange(std::uint32_t begin, std::uint32_t count, std::span<std::uint32_t> out);

} // namespace omicron
