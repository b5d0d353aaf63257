// The octree while it is being built: per-level node arrays that a renderer reads without
// locks while the builder appends.
//
// Nodes of one level are stored in Morton order (the builder creates them in that order: see
// oblique_cut.hpp), in a ChunkedArena that never moves them, so the children of a node are one
// index range of the next level and a node is found by binary search. Publication protocol:
//   - the builder fully writes nodes (and their samples and splat attributes), then stores the
//     level's node count with release: a reader that loads nodeCount() with acquire may read
//     every node below it, forever unchanged;
//   - after creating the parents of level l's roots up to a delimiter, the builder publishes
//     fixedThrough(l); after a whole fix pass, cutDelimiter() (the paper's m_C); both release.
// What a render front may hold (invariant 2.2: no root of the cut, no child of a root) follows
// from these delimiters alone: see isSettled().
// The builder also keeps an append-only insertion log: every leaf it concatenates to the cut,
// in span order, published with a release count like the nodes. A render front appends one
// placeholder per entry (see front.hpp) and so learns of new leaves without a queue or a lock.
#pragma once

#include "build/chunked_arena.hpp"
#include "build/node_residency.hpp"
#include "build/octree_node.hpp"
#include "build/sample_store.hpp"
#include "build/splat_estimator.hpp"
#include "build/stored_splats.hpp"
#include "points/sorted_cloud.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

namespace omicron {

// A view of the published cut (load it once per front evaluation). Each value only grows.
struct PublishedCut {
    morton::Code delimiter = 0; // m_C of the last complete fix pass; 0 before the first
    // Per level l >= 1: the delimiter level l was last fixed with (fixedThrough(l)). Passes
    // that stop part way up for new input (multipass) advance the deep levels only.
    std::array<morton::Code, morton::kMaxLevel + 1> fixedThrough{};
    std::uint64_t epoch = 0; // bumped whenever anything is published
    bool complete = false;   // the build finished: every node is settled
};

// One entry of the insertion log: a leaf the builder concatenated to the cut. A leaf at
// maxLevel is a node already (published with its level); a collapsed leaf (shallower) travels
// the cut as a placeholder and becomes a node when fix reaches its level. Either way the entry
// names the leaf itself, and entries are in span order (the order of concatenation).
struct CutInsertion {
    morton::Code leafCode = 0;      // the leaf's own code, at its own level
    std::uint32_t coveredBegin = 0; // the SortedCloud range the leaf covers
    std::uint32_t coveredCount = 0;
    std::chrono::steady_clock::time_point publishedAt{}; // when the builder published it
};

// Where the splat attributes of a hierarchy's points come from.
enum class SplatSource {
    Estimated, // a build: estimated per node when asked for (splat_estimator.hpp)
    Stored,    // a loaded .omh file: one stored record per held point (stored_splats.hpp)
    // A loaded .omh file of version 3: stored for the points of nodes too sparse for an
    // estimate of their own (which borrows points of other nodes), estimated for the others.
    StoredForSparseNodes,
};

class Hierarchy {
public:
    static constexpr std::size_t kInsertionsPerChunk = 4096;

    static constexpr std::size_t kNodesPerChunk = 1024;

    Hierarchy(std::shared_ptr<const SortedCloud> cloud, int maxLevel,
              SplatSource splatSource = SplatSource::Estimated);

    Hierarchy(const Hierarchy&) = delete;
    Hierarchy& operator=(const Hierarchy&) = delete;

    int maxLevel() const { return m_maxLevel; }
    const SortedCloud& cloud() const { return *m_cloud; }
    const std::shared_ptr<const SortedCloud>& sharedCloud() const { return m_cloud; }
    // True when splat normals are estimated (the cloud has no normals of its own).
    bool estimatesNormals() const { return !m_cloud->attributes().has(Attribute::Normal); }

    // ---- Reader side: any thread, no locks. ----

    // Published nodes of `level` (acquire). Nodes [0, nodeCount) are complete and immutable.
    std::size_t nodeCount(int level) const {
        return m_levels[level]->published.load(std::memory_order_acquire);
    }
    // `index` must be below a nodeCount(level) this thread loaded.
    const OctreeNode& node(int level, std::size_t index) const {
        return m_levels[level]->nodes[index];
    }
    // The splat attributes of the points `node` (a published node) holds, in its order: the
    // stored ones, or an estimate from the node's points. Any thread; `scratch` is the caller's.
    void nodeSplats(const OctreeNode& node, NodeSplats& out, SplatScratch& scratch) const;
    // What a node with too few points for an estimate of its own borrows its shape from: a
    // maxLevel leaf its sibling group (inserted whole, so published with it), a node holding a
    // sample its covered range.
    SparseSplatRegion sparseSplatRegion(const OctreeNode& node) const;

    // Which nodes' points are in memory when they are paged in on demand (a large .omh);
    // nullptr when every published node's points are (node_residency.hpp). A service the
    // render front talks to, so non-const through a const hierarchy.
    NodeResidency* residency() const { return m_residency.get(); }
    // True when node `index` of `level` (published) may have its points read now.
    bool pointsResident(int level, std::size_t index) const {
        return !m_residency || m_residency->resident(level, static_cast<std::uint32_t>(index));
    }

    // Index of the node with `code` among the first `count` nodes of its level (Morton order).
    std::optional<std::size_t> findNode(morton::Code code, std::size_t count) const;

    PublishedCut publishedCut() const;
    // Every root of level `level` has a parent with span > fixedThrough(level); every sibling
    // group with parent span <= it has its parent (acquire). 0 before level's first fix.
    morton::Code fixedThrough(int level) const {
        return m_levels[level]->fixedThrough.load(std::memory_order_acquire);
    }

    // True when a published node with `code` is neither a root of the cut nor a child of one,
    // so its parent and grandparent exist, never change, and it may enter a render front
    // (invariant 2.2): span(grandparent) <= cut.fixedThrough[level - 1] (the grandparent was
    // made when level - 1 was fixed), or the build is complete. The children of a settled
    // node are settled. Using cut.delimiter instead (the paper's single m_C) is also correct,
    // only more conservative.
    static bool isSettled(morton::Code code, const PublishedCut& cut, int maxLevel);

    // Entries of the insertion log published so far (acquire); [0, insertionCount) never
    // change. Empty for a hierarchy not grown by a builder (a loaded file).
    std::size_t insertionCount() const {
        return m_insertions.published.load(std::memory_order_acquire);
    }
    // `index` must be below an insertionCount() this thread loaded.
    const CutInsertion& insertion(std::size_t index) const { return m_insertions.entries[index]; }

    // ---- Builder side: one thread. ----

    // Appends a complete node to `level` (Morton order). Not visible before publishNodes().
    std::size_t appendNode(int level, const OctreeNode& node);
    std::size_t builtNodeCount(int level) const { return m_levels[level]->nodes.size(); }
    // Appends `count` unwritten nodes to `level` and returns the first one's index; each is
    // assigned whole through builtNode() (by any thread, in Morton order of index, before
    // publishNodes()).
    std::size_t extendNodes(int level, std::size_t count) {
        return m_levels[level]->nodes.extend(count);
    }
    OctreeNode& builtNode(int level, std::size_t index) {
        return m_levels[level]->nodes.slot(index);
    }
    // Keeps a buffer of samples a worker filled (no copy); returns where its elements now live.
    const std::uint32_t* adoptSamples(SampleBuffer&& samples) {
        return m_samples.adopt(std::move(samples));
    }
    StoredSplats& mutableStoredSplats() { return *m_storedSplats; } // SplatSource::Stored*
    // Set once, before the hierarchy is shared. The hierarchy owns it and destroys it first,
    // so its loading threads stop before the cloud and splats they write go away.
    void setResidency(std::unique_ptr<NodeResidency> residency) {
        m_residency = std::move(residency);
    }

    void publishNodes(int level);
    // Appends `count` unwritten entries to the insertion log (span order), assigned through
    // builtInsertion() as extendNodes() says; not visible before publishInsertions().
    std::size_t extendInsertions(std::size_t count) { return m_insertions.entries.extend(count); }
    CutInsertion& builtInsertion(std::size_t index) { return m_insertions.entries.slot(index); }
    void publishInsertions();
    void publishFixedThrough(int level, morton::Code delimiter);
    void publishCutDelimiter(morton::Code delimiter);
    void markComplete();

    // Memory held by the hierarchy itself (the SortedCloud it indexes is not included).
    std::size_t nodeBytes() const;
    std::size_t sampleBytes() const { return m_samples.bytesAllocated(); }
    std::size_t insertionLogBytes() const { return m_insertions.entries.bytesAllocated(); }
    std::size_t splatBytes() const { return m_storedSplats ? m_storedSplats->bytesResident() : 0; }

private:
    struct Level {
        explicit Level(std::size_t capacity) : nodes(capacity) {}
        ChunkedArena<OctreeNode, kNodesPerChunk> nodes;
        std::atomic<std::size_t> published{0};
        std::atomic<morton::Code> fixedThrough{0};
    };

    struct InsertionLog {
        explicit InsertionLog(std::size_t capacity) : entries(capacity) {}
        ChunkedArena<CutInsertion, kInsertionsPerChunk> entries;
        std::atomic<std::size_t> published{0};
    };

    void bumpEpoch() { m_epoch.fetch_add(1, std::memory_order_release); }

    std::shared_ptr<const SortedCloud> m_cloud;
    int m_maxLevel;
    std::vector<std::unique_ptr<Level>> m_levels;
    InsertionLog m_insertions; // every leaf covers at least one point: capacity = the cloud's
    SampleStore m_samples;
    std::unique_ptr<StoredSplats> m_storedSplats; // SplatSource::Stored*
    std::atomic<morton::Code> m_cutDelimiter{0};
    std::atomic<std::uint64_t> m_epoch{0};
    std::atomic<bool> m_complete{false};
    // Last: destroyed first (see setResidency).
    std::unique_ptr<NodeResidency> m_residency;
};

} // namespace omicron
