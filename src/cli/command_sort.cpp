// omicron-cli sort: pipeline 1 to disk. Reads any cloud, sorts it incrementally in Morton
// order and writes the sorted stream (.oms) while the sorted ranges come out.
#include "cli_args.hpp"
#include "commands.hpp"
#include "sort_to_oms.hpp"

#include <cstdio>
#include <tbb/global_control.h>

namespace omicron::cli {

namespace {

int runSort(const std::vector<std::string>& args) {
    const ParsedArgs parsed =
        parseArgs(args, withOptions({{"chunks", true}, {"threads", true}}, kMemoryOptionSpecs));
    if (parsed.help) {
        printCommandHelp(sortCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN and OUT.oms, found " +
                         std::to_string(parsed.positionals.size()) + " arguments");
    }
    const std::string& inPath = parsed.positionals[0];
    const std::string& outPath = parsed.positionals[1];
    SortOptions options;
    options.chunks = sortChunksOption(parsed);
    const MemoryOptions memory = memoryOptions(parsed, outPath);
    options.memoryBudgetBytes = memory.budgetBytes;
    options.tempDir = memory.tempDir;
    options.previewPoints = 0; // nothing shows it
    const int threads = threadsOption(parsed);
    tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(threads));

    const SortToOmsResult sorted = sortToOms(inPath, outPath, options);
    std::printf("sorted %llu points (%llu non-finite skipped) into %s: read %.3f s, first "
                "sorted batch %.3f s after reading, sort and write %.3f s, %d %s, "
                "%d threads\n",
                static_cast<unsigned long long>(sorted.written),
                static_cast<unsigned long long>(sorted.skippedNonFinite), outPath.c_str(),
                sorted.readSeconds, sorted.firstSortedSeconds, sorted.sortSeconds, sorted.chunks,
                sorted.spilled ? "runs merged (spilled to the scratch folder, now removed)"
                               : "chunks",
                threads);
    return 0;
}

} // namespace

const Command& sortCommand() {
    static const Command command{
        "sort", "sort a cloud in Morton order into a sorted stream file (.oms)",
        "sort IN OUT.oms [--chunks K] [--threads T] [--memory-budget SIZE] [--temp-dir DIR]",
        "Reads IN (PLY, LAS, LAZ or XYZ), sorts its points by their level-21 Morton code in the\n"
        "cube of its bounding box (origin = min corner, edge = largest extent) and writes the\n"
        "sorted stream OUT.oms (docs/FORMATS.md) while sorted chunks come out. OUT is written\n"
        "to a temporary file and renamed at the end: a failed sort leaves no partial file.\n"
        "\n"
        "  --chunks K   sort chunks, 1..256 (default 32): more chunks give the first sorted\n"
        "               batch sooner after reading ends\n"
        "  --threads T  worker threads (default: all cores)\n"
        "  --memory-budget SIZE\n"
        "               what the sort may keep resident, e.g. 512M or 4G (default: half of\n"
        "               physical memory). A cloud whose in-memory sort needs more (about 43\n"
        "               bytes a point with colour) is sorted in runs on disk, which are then\n"
        "               merged straight into OUT: memory stays within the budget at any size\n"
        "  --temp-dir DIR\n"
        "               where the runs go (default: OUT's folder); they need about the\n"
        "               size of OUT and are removed on success, error and Ctrl+C\n"
        "\n"
        "Progress goes to stderr. Exit status: 0 ok, 1 input or output error (a full scratch\n"
        "disk names the folder and the bytes needed), 2 usage error, 130 interrupted.\n",
        runSort};
    return command;
}

} // namespace omicron::cli
