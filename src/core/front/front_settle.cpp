#include "front/front_settle.hpp"

#include "build/hierarchy.hpp"

#include <chrono>
#include <thread>

namespace omicron {

namespace {

// Paged points: evaluations in a row that must change nothing with no load outstanding.
constexpr int kQuietEvaluationsPaged = 3;

} // namespace

SettleResult settleFront(Front& front, const FrontCamera& camera, const FrontOptions& options,
                         const SettleLimits& limits,
                         const std::function<void()>& afterEvaluation) {
    using Clock = std::chrono::steady_clock;
    const NodeResidency* residency = front.hierarchy().residency();
    const auto pendingLoads = [&]() -> std::uint64_t {
        return residency != nullptr ? residency->stats().pendingLoads : 0;
    };
    const int quietNeeded = residency != nullptr ? kQuietEvaluationsPaged : 1;
    const auto start = Clock::now();
    SettleResult result;
    for (int quiet = 0; quiet < quietNeeded;) {
        if (result.evaluations >= limits.maxEvaluations ||
            std::chrono::duration<double>(Clock::now() - start).count() >= limits.maxSeconds) {
            return result;
        }
        result.pendingBefore = pendingLoads();
        const FrontEvaluation evaluation = front.evaluate(camera, options);
        ++result.evaluations;
        if (afterEvaluation) {
            afterEvaluation();
        }
        const bool changed = evaluation.placeholdersInserted + evaluation.substituted +
                                 evaluation.branched + evaluation.pruned >
                             0;
        const bool still = !changed && evaluation.finishedSweep && result.pendingBefore == 0 &&
                           pendingLoads() == 0;
        quiet = still ? quiet + 1 : 0;
        if (residency != nullptr && !changed && quiet < quietNeeded) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1)); // the loader is reading
        }
    }
    result.settled = true;
    return result;
}

} // namespace omicron
