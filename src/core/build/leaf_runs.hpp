// Cutting the sorted stream into the leaves of a depth-maxLevel octree.
//
// A leaf is a run of points (in Morton order) that share their cell at maxLevel; Morton order
// makes every such run contiguous. A range handed over by the sorter can end in the middle of
// a run (or, for leaf collapse, of a sibling group), so the tail of the input is held back
// until the next range or the end of input says where it stops. Everything works on the
// points' unit-cube positions (their codes are morton::encodeUnit of them), read through a
// PositionView (either point store); the span overloads read a plain array.
#pragma once

#include "points/block_codes.hpp"
#include "points/morton.hpp"
#include "points/position_views.hpp"

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

namespace omicron {

struct LeafRun {
    morton::Code code = 0; // at maxLevel
    std::uint32_t begin = 0;
    std::uint32_t count = 0;
};

// The end of the index range [begin, end) of points that share the cell of positions[begin] at
// `level` (exponential then binary search: O(log run length)).
template <PositionView Positions>
std::size_t endOfRun(const Positions& positions, std::size_t begin, std::size_t end, int level);

// The start of the run of points sharing the cell of positions[last] at `level` that ends at
// `last` (inclusive): the mirror of endOfRun, searching towards the front.
template <PositionView Positions>
std::size_t startOfRun(const Positions& positions, std::size_t last, int level);

// Appends to `runs` the leaves at maxLevel of positions[begin, end) (in parallel blocks),
// reading the positions only where `index` (the cloud's block codes, block_codes.hpp; covering
// at least [0, end), or empty) says a cell changes.
template <PositionView Positions>
void findLeafRuns(const Positions& positions, BlockCodes index, std::size_t begin,
                  std::size_t end, int maxLevel, std::vector<LeafRun>& runs);

// How far [begin, available) may be cut into leaves now, taking at most about `limit` points:
// the returned end never splits a group of points sharing their cell at `groupLevel` (a leaf,
// or a sibling group when leaf collapse must see a leaf's siblings), unless `inputEnded`.
// Returns `begin` when the only group in reach may still grow with later input.
template <PositionView Positions>
std::size_t insertableEnd(const Positions& positions, std::size_t begin, std::size_t available,
                          bool inputEnded, int groupLevel, std::size_t limit);

#define OMICRON_LEAF_RUNS_EXTERN(Positions)                                                      \
    extern template std::size_t endOfRun(const Positions&, std::size_t, std::size_t, int);      \
    extern template std::size_t startOfRun(const Positions&, std::size_t, int);                 \
    extern template void findLeafRuns(const Positions&, BlockCodes, std::size_t, std::size_t,   \
                                      int, std::vector<LeafRun>&);                              \
    extern template std::size_t insertableEnd(const Positions&, std::size_t, std::size_t, bool, \
                                              int, std::size_t);
OMICRON_LEAF_RUNS_EXTERN(ExactPositions)
OMICRON_LEAF_RUNS_EXTERN(PackedPositions)
#undef OMICRON_LEAF_RUNS_EXTERN

// The same over a plain array of positions.
inline std::size_t endOfRun(std::span<const glm::vec3> positions, std::size_t begin,
                            std::size_t end, int level) {
    return endOfRun(ExactPositions{positions.data()}, begin, end, level);
}
inline std::size_t startOfRun(std::span<const glm::vec3> positions, std::size_t last, int level) {
    return startOfRun(ExactPositions{positions.data()}, last, level);
}
inline void findLeafRuns(std::span<const glm::vec3> positions, BlockCodes index,
                         std::size_t begin, std::size_t end, int maxLevel,
                         std::vector<LeafRun>& runs) {
    findLeafRuns(ExactPositions{positions.data()}, index, begin, end, maxLevel, runs);
}
inline std::size_t insertableEnd(std::span<const glm::vec3> positions, std::size_t begin,
                                 std::size_t available, bool inputEnded, int groupLevel,
                                 std::size_t limit) {
    return insertableEnd(ExactPositions{positions.data()}, begin, available, inputEnded,
                         groupLevel, limit);
}

} // namespace omicron
