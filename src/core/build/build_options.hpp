// Parameters of the hierarchy build (the paper's depth, worklist size, ratio, leaf collapse).
#pragma once

#include "points/morton.hpp"

#include <cstddef>
#include <string>

namespace omicron {

// What happens to a maxLevel leaf that has no siblings (a chain under its parent).
enum class LeafCollapse {
    Off,      // keep it: the finished leaves hold exactly the input points
    Lossless, // its parent becomes the leaf and holds all of its points
    Paper,    // the paper's variant: its parent becomes the leaf with only its sample; the
              // other points are dropped and counted in BuildStatistics::droppedPoints
};

const char* toString(LeafCollapse collapse);

// Measured on autzen_south (4.84M points, depth 7, in-memory sorted stream, 2 cores, two
// runs): 8 / 16 / 32 / 64 / 128 -> 5.4-4.5 / 4.4-4.5 / 4.0-3.8 / 4.3-3.4 / 3.9-3.6 ms, with
// 3400 / 1706 / 859 / 438 / 226 work items and 2663 / 1319 / 665 / 329 / 161 sibling groups
// split by a worklist boundary. From 32 up the differences are within this machine's noise;
// 32 is also inside the paper's best front range (32-64).
inline constexpr std::size_t kDefaultWorklistSize = 32;

// The debug preset (OMICRON_CHECK_INVARIANTS) checks the cut after every fix pass by default.
#ifdef OMICRON_CHECK_INVARIANTS
inline constexpr bool kCheckInvariantsByDefault = true;
#else
inline constexpr bool kCheckInvariantsByDefault = false;
#endif

struct BuildOptions {
    int maxLevel = 7;                                // hierarchy depth l_max, 1..21
    double ratio = 0.2;                              // parent points / children points, (0, 1]
    std::size_t worklistSize = kDefaultWorklistSize; // nodes per parallel work item, >= 1
    LeafCollapse collapse = LeafCollapse::Off;
    int threads = 0; // 0: all cores
    // Run checkCutInvariants() after every fix pass; the first violation is recorded in
    // BuildStatistics::invariantViolation (and aborts under OMICRON_CHECK_INVARIANTS).
    bool checkInvariants = kCheckInvariantsByDefault;
};

// Throws std::invalid_argument naming the first parameter out of range.
void validate(const BuildOptions& options);

} // namespace omicron
