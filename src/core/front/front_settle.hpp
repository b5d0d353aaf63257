// Evaluating a front until it stops changing, for a still image: a screenshot, the CLI's
// render, tests and benchmarks.
//
// Over points in memory, one evaluation that changes nothing and finishes its sweep is enough.
// Over points paged in on demand (Hierarchy::residency()), the front waits for the nodes it
// asked for: it is settled after several such evaluations in a row with no node load
// outstanding before or after each (a load may land during an evaluation, which only the
// next one sees), pausing a millisecond after an unchanged one while the loader reads.
#pragma once

#include "front/front.hpp"

#include <climits>
#include <cstdint>
#include <functional>
#include <limits>

namespace omicron {

struct SettleLimits {
    int maxEvaluations = INT_MAX;
    double maxSeconds = std::numeric_limits<double>::infinity();
};

struct SettleResult {
    int evaluations = 0;
    bool settled = false; // false: a limit was reached first
    // Paged points: loads outstanding before the last evaluation.
    std::uint64_t pendingBefore = 0;
};

// `afterEvaluation` runs after each evaluation (e.g. a test's invariant check).
SettleResult settleFront(Front& front, const FrontCamera& camera, const FrontOptions& options,
                         const SettleLimits& limits,
                         const std::function<void()>& afterEvaluation = {});

} // namespace omicron
