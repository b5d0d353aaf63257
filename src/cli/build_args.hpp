// The build parameters of every command that builds a hierarchy (build, export-potree): depth,
// ratio, worklist, leaf collapse, threads, sort chunks and point store, parsed one way.
#pragma once

#include "build/build_options.hpp"
#include "cli_args.hpp"
#include "points/sorted_cloud.hpp"

#include <vector>

namespace omicron::cli {

inline const std::vector<OptionSpec> kBuildOptionSpecs{
    {"depth", true},   {"ratio", true},  {"worklist", true}, {"collapse", true},
    {"threads", true}, {"chunks", true}, {"store", true}};

struct BuildArgs {
    BuildOptions options; // threads included
    int threads = 1;      // for the caller's tbb::global_control
    int sortChunks = 0;
    PointStorage storage = PointStorage::Exact;
};

// The options above, defaults where absent; throws UsageError naming the option.
BuildArgs buildArgs(const ParsedArgs& parsed);

} // namespace omicron::cli
