// Pipeline 1 to a .oms file, shared by `sort` and `convert IN OUT.oms`: sorted in memory when
// the sort fits the memory budget, else in runs on disk merged straight into the file (the
// sorted cloud is never held, so memory stays within the budget whatever the size). Progress
// on stderr; Ctrl+C stops between batches (Interrupted), and the runs and the temporary
// output are removed on every way out.
#pragma once

#include "sort/morton_sorter.hpp"

#include <cstdint>
#include <string>

namespace omicron::cli {

struct SortToOmsResult {
    std::uint64_t written = 0;
    std::uint64_t skippedNonFinite = 0;
    double readSeconds = 0.0;
    double firstSortedSeconds = 0.0; // after reading ends
    double sortSeconds = 0.0;        // sort (or merge) and write, after reading ends
    int chunks = 0;                  // sort chunks, or runs merged when spilled
    bool spilled = false;
    std::string scratchParent; // where the runs went (spilled only)
};

// `options.cancel` is set here (Ctrl+C). Throws InputError, OutputError, Interrupted.
SortToOmsResult sortToOms(const std::string& inPath, const std::string& outPath,
                          SortOptions options);

} // namespace omicron::cli
