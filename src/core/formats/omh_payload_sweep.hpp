// The point records of the deep levels of a .omh, written in one pass over the sorted cloud.
//
// The file stores level after level, and each level's nodes cover the whole cloud: written a
// level at a time, a save reads the cloud once per level, and for a cloud in a scratch file
// (beyond the memory budget) each dense level is a full re-read of that file. Here the levels
// from `firstLevel` down are filled side by side instead — each at its own offset in a file
// already extended to its full size — while the cloud is swept once in Morton order, a batch
// of subtrees at a time: every node at those levels lies inside one subtree of `firstLevel`,
// and in a built hierarchy a subtree's points are one stretch of the cloud, which is read
// ahead in bulk, used, and released under the budget before the next batch. Batches follow
// the child links, not the covered ranges, so a hierarchy loaded from a .omh (whose nodes
// hold their own records) is swept the same way.
#pragma once

#include "build/hierarchy.hpp"
#include "formats/omh_column_sink.hpp"
#include "formats/omh_format.hpp"
#include "io/atomic_file_writer.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace omicron {

// Per level, per node: the points held by the node and all its descendants.
using SubtreePoints = std::vector<std::vector<std::uint64_t>>;
SubtreePoints subtreeHeldPoints(const Hierarchy& hierarchy);

// The shallowest level whose every subtree holds at most `maxBatchPoints` points (the deepest
// level if none does): from there the sweep's batches are bounded.
int omhSweepFirstLevel(const SubtreePoints& subtrees, std::uint64_t maxBatchPoints);

// Writes the records of levels [firstLevel, maxLevel] at the payload offsets of `levels`
// (the file extended past them), filling in their payload checksums; `afterLevel` is called
// for each level once all its records were handed to the file. A batch of subtrees holds at
// most `maxBatchPoints` points (their splat attributes wait in memory until written) unless
// one subtree alone holds more. `afterRead` (may be empty) is called on the calling thread
// once a batch's stretch of the cloud has been read, with the stretch's end: the points before
// it are in memory now (a built hierarchy's batches cover the cloud front to back).
// `deepestColumns` (version 4; null before) takes the deepest level's nodes, stored as
// columns, in place of its records.
void writeOmhLevelsInOneSweep(AtomicFileWriter& file, const Hierarchy& hierarchy,
                              const omh::RecordLayout& layout, std::vector<omh::LevelEntry>& levels,
                              const SubtreePoints& subtrees, int firstLevel,
                              std::uint64_t maxBatchPoints,
                              const std::function<void(int level)>& afterLevel,
                              const std::function<void(std::uint64_t readEnd)>& afterRead,
                              OmhColumnSink* deepestColumns);

} // namespace omicron
