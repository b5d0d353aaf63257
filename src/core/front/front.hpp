// The Oblique Hierarchy Cut Front (paper, section "Oblique Hierarchy Cut Front"): the set of
// nodes the renderer draws, tracked from frame to frame while the hierarchy grows.
//
// The render thread owns a Front outright; the builder never touches it. Everything the front
// learns about the hierarchy comes from what the Hierarchy published (acquire loads), so no
// lock is taken on the hot path:
//   - bottom-up (a hierarchy still being built when the front first looks at it): every leaf
//     the builder concatenates to the cut enters the front as a placeholder, appended in span
//     order (invariant 2.1); a placeholder is substituted by its leaf once the leaf is settled
//     (Hierarchy::isSettled: not a root of L_C nor a child of one, invariant 2.2), checking one
//     level per evaluation (the level with the most settled leaves waiting), so every leaf is
//     substituted within maxLevel - 1 evaluations of its settling;
//   - top-down (a hierarchy complete when the front first looks at it: a finished build, or a
//     .omh file being loaded level by level): the front starts at the root; a node branches
//     only into children already published (nodeCount of the next level).
// Then the usual operators: branch (a node is replaced by its children) when its projected
// size exceeds the threshold, prune (a complete sibling group is replaced by its settled
// parent) when the parent's projected size falls below it; placeholders are never pruned.
// A point budget coarsens the front until the points of its visible nodes fit, as Potree's
// does. An evaluation may be split over several frames (a CPU time budget per call).
#pragma once

#include "build/hierarchy.hpp"
#include "points/clip_box.hpp"
#include "points/morton.hpp"

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace omicron {

// The camera as the front sees it, in the hierarchy's unit cube.
struct FrontCamera {
    glm::dmat4 viewProjection{1.0}; // unit cube -> clip space (frustum culling)
    glm::dvec3 eye{0.5, 0.5, 2.0};  // eye position in the unit cube (perspective)
    // Pixels covered by a unit length at unit distance: viewportHeight / (2 tan(fovY / 2)).
    // For an orthographic camera: pixels per unit length (distance is then ignored).
    double pixelsPerUnitAtUnitDistance = 1000.0;
    bool orthographic = false;
    // Only what lies in this box (unit cube) is drawn: cells wholly outside are culled.
    std::optional<ClipBox> clip;
};

struct FrontOptions {
    // A node whose projected size (its cell's diagonal, in pixels) exceeds this branches; a
    // sibling group whose parent projects below it is pruned.
    double projectionThresholdPx = 100.0;
    // Most points the visible front nodes may hold; 0 = no budget. Holds after every
    // evaluate() (branches that would exceed it wait, the front coarsens when over it) unless
    // FrontEvaluation::overBudget says nothing more could be pruned.
    std::size_t pointBudget = 4'000'000;
    // CPU time one evaluate() call may spend; 0 = evaluate the whole front every call.
    double cpuBudgetMs = 2.0;
};

// One node of the front. Placeholders stand for leaves that are not settled yet; they draw
// nothing.
struct FrontEntry {
    morton::Code code = 0;   // the node's code (a placeholder: the leaf's code)
    // Index in its level's node array; a placeholder: its entry in Hierarchy::insertion().
    std::uint32_t index = 0;
    bool placeholder = false;
    bool visible = false; // in the view frustum at the last evaluation (always false: placeholder)
    int level() const { return morton::level(code); }
};

struct FrontEvaluation {
    double cpuMs = 0.0;
    bool finishedSweep = false; // the evaluation reached the end of the front (not cut by budget)
    std::size_t placeholdersInserted = 0;
    std::size_t substituted = 0;
    std::size_t branched = 0;
    std::size_t pruned = 0;
    std::size_t visibleNodes = 0;
    std::size_t visiblePoints = 0; // points held by visible, non-placeholder entries
    std::size_t frontSize = 0;     // entries after the call, placeholders included
    std::size_t placeholders = 0;  // placeholders after the call
    int substitutionLevel = -1;    // level the current sweep substitutes (-1: none ready)
    // The point budget could not be met: every group that may be pruned was (placeholders
    // and unsettled parents cannot be).
    bool overBudget = false;
};

class Front {
public:
    // The front keeps `hierarchy` alive.
    explicit Front(std::shared_ptr<const Hierarchy> hierarchy);
    ~Front();
    Front(Front&&) noexcept;
    Front& operator=(Front&&) noexcept;

    // Takes what the hierarchy published since the last call, then evaluates (part of) the
    // front against `camera`. Render thread only.
    FrontEvaluation evaluate(const FrontCamera& camera, const FrontOptions& options);

    // The front in span order (invariant 2.1).
    std::span<const FrontEntry> entries() const;
    std::size_t placeholderCount() const;
    // Entries of the front at each level 0..maxLevel (placeholders at their leaf's level);
    // sums to entries().size(). Kept current by every change, so reading it costs nothing.
    std::span<const std::size_t> entriesPerLevel() const;

    const Hierarchy& hierarchy() const;

    // Seconds between the builder publishing a leaf and the front substituting it, for every
    // leaf substituted so far (front_bench's insertion delay); cleared by the call.
    std::vector<double> takeSubstitutionDelays();
    // For the same leaves: evaluate() calls from the evaluation that first found the leaf
    // ready (published and settled) to the one that substituted it (0: the same call);
    // cleared by the call.
    std::vector<std::uint32_t> takeSubstitutionEvaluationDelays();

    // Empty when invariants 2.1 and 2.2 hold (and every entry is a published node or a
    // placeholder for a leaf the builder concatenated); otherwise what is wrong. Debug builds
    // (OMICRON_CHECK_INVARIANTS) run it after every evaluate().
    std::string checkInvariants() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

} // namespace omicron
