// Which points each node stores in an additive octree, the kind Potree reads.
//
// A Potree viewer draws a node together with its visible descendants, so each input point is
// stored once, in the shallowest node that holds it. omicron's hierarchy is not additive: a
// parent holds a copy of a sample of its children's held points (build/parent_sampler.hpp).
// The held sets are therefore nested along every path (whatever a node holds inside a child's
// cell, that child holds too), and a node's additive points are the points it holds minus
// those its parent holds. Over all nodes they are every point some leaf holds, each once: the
// input, less what the paper's leaf collapse dropped.
//
// The parent's held list is a subsequence of its children's held lists concatenated in node
// order (the sampler picks from that list in order, and both are in Morton order), so one
// merge per sibling group finds the parent's points among the children's: O(points held) in
// all, one sibling group in memory at a time.
//
// What "the same point" means depends on the cloud. A built hierarchy indexes one Morton-order
// cloud, and a parent holds the child's very index. A loaded .omh (CloudOrder::NodeOrder)
// stores every node's points separately, so the parent's copy is another index with an equal
// record (position, normal, colour, intensity). The merge then takes the first equal record:
// points with equal records are indistinguishable and lie in the same cell, so each child
// keeps the right multiset.
#pragma once

#include "build/hierarchy.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>

namespace omicron {

// A hierarchy whose nodes are not nested samples of their children (a damaged .omh file):
// what() names the level and the node.
class NotNestedError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// visit(level, index, points): `points` are the SortedCloud indices node `index` of `level`
// stores, in the node's order (possibly none: the parent took them all).
using AdditiveNodeVisitor =
    std::function<void(int level, std::size_t index, std::span<const std::uint32_t> points)>;

// Calls `visit` for every node of the complete `hierarchy`, level by level and in node order
// within a level (a parent's children are visited together, after the parent's level). The
// visitor may throw to stop the walk. Throws NotNestedError when a parent holds a point none of
// its children holds, or a level's nodes are not exactly its parents' children.
void visitAdditiveNodes(const Hierarchy& hierarchy, const AdditiveNodeVisitor& visit);

} // namespace omicron
