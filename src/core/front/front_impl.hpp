// Front's private state, shared by front.cpp (intake and sweep), front_budget.cpp (branching
// and the point budget) and front_invariants.cpp. Not part of the public API.
#pragma once

#include "front/front.hpp"
#include "front/front_projection.hpp"
#include "front/front_substitution.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace omicron {

// Finds parents while the front is walked in span order: the parents a walk meets at one
// level are in ascending Morton order, so each level's search resumes where the last ended.
class ParentCursor {
public:
    void reset() { m_next.fill(0); }
    // Index of the node `code` among the first `count` of its level, if published.
    std::optional<std::size_t> find(const Hierarchy& hierarchy, morton::Code code,
                                    std::size_t count);

private:
    std::array<std::size_t, morton::kMaxLevel + 1> m_next{};
};

struct Front::Impl {
    enum class Mode {
        Undecided, // nothing seen yet
        BottomUp,  // placeholders from the builder's insertion log
        TopDown,   // from the root of a complete hierarchy
    };

    // A node that wants to branch, found by the sweep; branched at the end of the call, the
    // largest first, as far as the point budget allows.
    struct BranchCandidate {
        std::size_t position = 0;
        double sizePx = 0.0;
    };

    // A complete sibling group of settled nodes in the front whose settled parent may replace
    // it (the point budget's coarsening and make-room steps).
    struct PrunableGroup {
        std::size_t position = 0;
        std::uint32_t members = 0;
        std::uint32_t parentIndex = 0;
        double parentSizePx = 0.0;
        bool parentVisible = false;
        std::int64_t pointsFreed = 0; // visible points the prune removes
        int parentLevel = 0;
        bool parentResident = true; // paged points: the parent can replace the group now
    };

    // An operation of a rebuild (end of a call): the entries [position, position + members)
    // become the parent, or the entry at position becomes its children.
    struct Rebuild {
        std::size_t position = 0;
        std::uint32_t members = 0; // prune: the group's size; branch: 0
        std::uint32_t nodeIndex = 0;
        bool branch = false;
    };

    explicit Impl(std::shared_ptr<const Hierarchy> shared);

    // front.cpp
    void loadPublished();
    void takeInsertions(FrontEvaluation& result);
    void startSweep(FrontEvaluation& result);
    bool sweep(const FrontOptions& options, FrontEvaluation& result);
    FrontEntry evaluateNode(FrontEntry entry, const OctreeNode& node);
    // The node's children are published and settled, so it may branch once they are resident.
    bool childrenReady(const OctreeNode& node, int level) const;
    // Paged points (hierarchy.residency()): asks for the node and says whether it is resident
    // now; always true when every node's points are in memory.
    bool wantResident(int level, std::size_t index, double priority) {
        return residency == nullptr ||
               residency->want(level, static_cast<std::uint32_t>(index), priority);
    }
    // Paged points: whether every child's points are in memory (always, unpaged), and the
    // request for the missing ones. applyBudget asks only for the children of branches the
    // point budget allows, so the requests of a frame stay within it.
    bool childrenResident(const OctreeNode& node, int level) const;
    // Paged points: a group may be pruned now when its parent is in memory; otherwise the
    // parent is asked for (only for the groups a prune would use).
    bool prunableNow(const PrunableGroup& group) {
        return group.parentResident ||
               wantResident(group.parentLevel, group.parentIndex, group.parentSizePx);
    }
    void requestChildren(const OctreeNode& node, int level, double priority);
    // Paged points: the entries are held for this frame, the rest may be evicted.
    void holdEntries();
    bool settled(morton::Code code) const {
        return Hierarchy::isSettled(code, cut, hierarchy.maxLevel());
    }
    void account(const FrontEntry& entry, int sign);

    // front_budget.cpp
    void applyBudget(const FrontOptions& options, FrontEvaluation& result);
    // Fills `groups` (smallest parent first) with the groups whose prune frees visible points
    // and whose parent projects below `parentSizeBelowPx`.
    void collectPrunableGroups(double parentSizeBelowPx);
    void rebuild(std::vector<Rebuild>& operations, FrontEvaluation& result);

    std::shared_ptr<const Hierarchy> shared;
    const Hierarchy& hierarchy;
    NodeResidency* residency; // hierarchy.residency(): null unless points are paged
    Mode mode = Mode::Undecided;

    // The front, in span order. Between calls it is contiguous; during a sweep the entries
    // [0, written) are done and [read, size) wait, with written <= read (a sweep only
    // substitutes 1 for 1 and prunes k for 1; branches grow the front at the end of a call).
    std::vector<FrontEntry> entries;
    std::size_t sweepPosition = 0; // where the current sweep resumes; 0: a new sweep
    bool sweepRunning = false;
    int substitutionLevel = -1;

    FrontSubstitution substitution;
    std::size_t insertionsTaken = 0;
    std::size_t placeholders = 0;
    std::uint64_t evaluations = 0;

    // What this call loaded (the cut first, then the node counts: a node the cut says is
    // settled is then always below its level's count).
    PublishedCut cut;
    std::array<std::size_t, morton::kMaxLevel + 1> nodeCounts{};
    FrontCamera camera;
    FrustumPlanes frustum;
    double thresholdPx = 0.0;

    // Visible entries and the points they hold, kept current with every change.
    std::size_t visibleNodes = 0;
    std::uint64_t visiblePoints = 0;
    // Entries per level (placeholders included), kept current by every operation that adds,
    // removes or replaces entries, so a renderer reads them per frame without a walk.
    std::array<std::size_t, morton::kMaxLevel + 1> levelCounts{};

    std::vector<double> delaysSeconds;
    std::vector<std::uint32_t> delaysEvaluations;

    // Scratch reused from call to call (no allocation in steady state).
    ParentCursor sweepParents;
    std::vector<BranchCandidate> candidates;
    std::vector<PrunableGroup> groups;
    std::vector<Rebuild> operations;
    std::vector<std::uint8_t> marks;
    std::vector<FrontEntry> rebuilt;
};

} // namespace omicron
