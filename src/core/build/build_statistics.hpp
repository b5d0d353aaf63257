// What a hierarchy build did and cost: the numbers the CLI prints and the GUI shows.
#pragma once

#include "points/sorted_cloud.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace omicron {

struct LevelStatistics {
    std::uint64_t nodes = 0;
    std::uint64_t leaves = 0;
    std::uint64_t points = 0; // points held by the level's nodes (samples for parents)
    // The oblique cut as the last fix pass left it (what the GUI's cut panel shows):
    std::uint64_t cutRoots = 0;            // entries of L_level, placeholders included
    std::uint64_t placeholdersPending = 0; // of those, placeholders still rising
    std::uint64_t placeholdersSubstituted = 0; // leaves of this level a placeholder became
};

struct BuildStatistics {
    // Seconds since the builder was constructed.
    double firstRangeSeconds = -1.0; // first sorted range received
    double inputEndSeconds = -1.0;   // finish() called: the last sorted range had arrived
    double creationSeconds = -1.0;   // the hierarchy was complete (or the build stopped)
    // Time at which 10 %, 20 %, ... 100 % of the cloud's points were inserted (concatenated into
    // the cut as leaves); -1 where not reached. The base is the SortedCloud's capacity.
    std::array<double, 10> milestonesSeconds{-1, -1, -1, -1, -1, -1, -1, -1, -1, -1};

    std::uint64_t inputPoints = 0;     // points inserted (== capacity when complete)
    std::uint64_t droppedPoints = 0;   // LeafCollapse::Paper: points no node holds any more
    std::uint64_t collapsedLeaves = 0; // leaves merged into their parent (either collapse mode)
    std::uint64_t placeholdersCreated = 0;
    std::uint64_t placeholdersSubstituted = 0;
    std::vector<LevelStatistics> levels; // index = level, 0..maxLevel

    std::uint64_t fixPasses = 0;              // passes started (multipass)
    std::uint64_t passesRestarted = 0;        // passes left part way up for fresher input
    std::uint64_t worklists = 0;              // parallel work items run (leaves and fix)
    std::uint64_t duplicateParentsMerged = 0; // sibling groups split by a worklist boundary

    PointStorage pointStorage = PointStorage::Exact; // how the cloud keeps its points
    std::size_t cloudBytes = 0; // the SortedCloud the nodes index (positions, colours, ...)
    std::size_t nodeBytes = 0;
    std::size_t sampleBytes = 0; // parents' sample index lists
    std::size_t splatBytes = 0;  // per-point radius (and estimated normal)
    std::size_t bytesResident() const { return cloudBytes + nodeBytes + sampleBytes + splatBytes; }

    bool complete = false;
    bool cancelled = false;
    std::string invariantViolation; // first failure of the checker (when it ran); empty if none

    std::uint64_t totalNodes() const;
};


// Records, in `milestones`, `seconds` for every decile that `inserted` of `total` points
// reached and that was not recorded yet.
void recordMilestones(std::array<double, 10>& milestones, std::uint64_t inserted,
                      std::uint64_t total, double seconds);

} // namespace omicron
