// The parallel OMiCroN builder: an octree grown bottom-up from a Morton-sorted stream with
// oblique cuts, readable by a renderer while it grows.
//
// Threads. The producer (the sorter's or the .oms reader's thread) only announces ranges:
// onSortedRange() records the new end of the published prefix and wakes the builder's master
// thread, so producing never waits for building. The master thread repeats fix passes:
//   1. insert: cut the new input into maxLevel leaves (holding back a sibling group that may
//      continue), append and publish them, and concatenate them to the cut (splat attributes
//      are not built: a renderer estimates them for the nodes it draws, splat_estimator.hpp);
//   2. fix, level by level from maxLevel up: the roots that fix moves at this level are cut
//      into worklists of `worklistSize` roots; oneTBB workers make the parent of each sibling
//      group in their worklist. A group cut by a worklist boundary would yield the paper's
//      duplicate parents, one per worklist; instead the worklist holding the group's first
//      root takes the whole group and the next one skips its rest, so the duplicates are
//      merged in parallel where they arise (no child lost, and the parent equals a sequential
//      fix's). The master appends the parents in Morton order and publishes the level. The
//      next level's worklists are cut again from the whole list, which merges the results
//      that shrank going up.
//   3. multipass: after each level, if new input arrived and it promises more work than the
//      next level holds, the pass stops there and a new pass starts from maxLevel with the
//      new leaves (the levels left behind are fixed by the new pass on its way up).
// Nodes are immutable once published, so a renderer reads them without locks: see
// hierarchy.hpp for the protocol and Hierarchy::isSettled() for what may enter a front.
//
// The result (nodes and samples) depends only on the input and the options: not on
// the thread count, the worklist size, the range sizes or the timing.
#pragma once

#include "build/build_options.hpp"
#include "build/build_statistics.hpp"
#include "build/hierarchy.hpp"
#include "build/leaf_runs.hpp"
#include "build/oblique_cut.hpp"
#include "sort/morton_sorter.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

namespace omicron {

class HierarchyBuilder {
public:
    // Validates `options` (std::invalid_argument) and starts the master thread, which waits
    // for ranges of `cloud`.
    HierarchyBuilder(std::shared_ptr<const SortedCloud> cloud, const BuildOptions& options);
    // Cancels a build still running and joins the master thread.
    ~HierarchyBuilder();

    HierarchyBuilder(const HierarchyBuilder&) = delete;
    HierarchyBuilder& operator=(const HierarchyBuilder&) = delete;

    // Producer side, the SortedRangeConsumer signature: [begin, end) of the builder's cloud is
    // published; ranges arrive in order and without gaps. Returns at once.
    void onSortedRange(const SortedCloud& cloud, std::size_t begin, std::size_t end);
    // A consumer for IncrementalMortonSorter / OmsReader that forwards to onSortedRange().
    SortedRangeConsumer consumer();
    // No more ranges will come: the builder completes the hierarchy.
    void finish();
    // Stops the build at the next level step (any thread, any time); the cut stays valid.
    void cancel();
    // Blocks until the build is complete or stopped; rethrows what the master thread threw.
    void wait();

    const BuildOptions& options() const { return m_options; }
    const Hierarchy& hierarchy() const { return *m_hierarchy; }
    std::shared_ptr<const Hierarchy> sharedHierarchy() const { return m_hierarchy; }
    // A snapshot, updated after every fix pass; complete after wait().
    BuildStatistics statistics() const;
    // The cut as the build left it. Only after wait().
    const ObliqueCut& cut() const { return m_cut; }

private:
    class Worker;

    void run();
    void buildLoop();
    bool waitForWork(bool passComplete, std::size_t& available, bool& inputEnded);
    void insertInput(std::size_t available, bool inputEnded);
    void publishLeaves(std::span<const LeafRun> runs, std::span<const CutRoot> roots,
                       std::size_t leaves);
    bool fixPass();
    void fixLevel(int level);
    bool shouldStartNewPass(int nextLevel) const;
    void checkInvariants(bool completePass);
    void publishStatistics();
    bool cancelRequested() const { return m_cancel.load(std::memory_order_relaxed); }
    double secondsSinceStart() const;

    BuildOptions m_options;
    std::shared_ptr<const SortedCloud> m_cloud;
    std::shared_ptr<Hierarchy> m_hierarchy;
    ObliqueCut m_cut;
    std::unique_ptr<Worker> m_worker;
    std::chrono::steady_clock::time_point m_start;

    // Producer -> master hand-off.
    mutable std::mutex m_inputMutex;
    std::condition_variable m_inputChanged;
    std::size_t m_available = 0; // end of the ranges received
    bool m_inputEnded = false;
    double m_firstRangeSeconds = -1.0;
    double m_inputEndSeconds = -1.0;
    std::atomic<std::size_t> m_availableHint{0}; // m_available, for the multipass decision
    std::atomic<bool> m_cancel{false};

    // Master thread state.
    std::size_t m_insertedEnd = 0;    // input cut into leaves and concatenated
    std::size_t m_takenAvailable = 0; // m_available when input was last taken
    bool m_inputBacklog = false;      // input was left for the next pass (per-pass limit)
    BuildStatistics m_stats;

    mutable std::mutex m_statsMutex;
    BuildStatistics m_publishedStats;

    std::mutex m_doneMutex;
    std::condition_variable m_doneChanged;
    bool m_done = false;
    std::exception_ptr m_error;
    std::thread m_thread; // last: starts after every member above exists
};

} // namespace omicron
