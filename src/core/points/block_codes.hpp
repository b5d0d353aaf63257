// A sparse index of a Morton-sorted cloud: the level-21 code of every 64th point.
//
// Codes are non-decreasing along the cloud, so when entries k and k + 1 fall into the same cell
// at level l, so does every point between them: no run of level-l cells starts inside block k.
// Cutting the stream into leaves (leaf_runs.hpp) reads the index and only the blocks where the
// cell changes, not every position: on autzen_south at depth 7, 24 % of the blocks, so about
// a quarter of the position bytes. The index costs 8 bytes per 64 points (0.125 B a point).
#pragma once

#include "points/morton.hpp"

#include <cstddef>
#include <span>

namespace omicron {

inline constexpr std::size_t kBlockCodePoints = 64;

// Entry k is the code of point k * kBlockCodePoints; an empty span means "no index".
using BlockCodes = std::span<const morton::Code>;

// The number of entries that describe points [0, end): those whose point is below `end`.
constexpr std::size_t blockCodeCount(std::size_t end) {
    return (end + kBlockCodePoints - 1) / kBlockCodePoints;
}

} // namespace omicron
