// omicron-cli sort: pipeline 1 to disk. Reads any cloud, sorts it incrementally in Morton
// order and writes the sorted stream (.oms) while the sorted ranges come out.
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/oms_writer.hpp"
#include "io/input_error.hpp"
#include "io/point_reader.hpp"
#include "progress_line.hpp"
#include "sort/morton_sorter.hpp"

#include <chrono>
#include <cstdio>
#include <tbb/global_control.h>

namespace omicron::cli {

namespace {

int runSort(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, {{"chunks", true}, {"threads", true}});
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
    const int threads = threadsOption(parsed);
    tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(threads));

    using Clock = std::chrono::steady_clock;
    const auto seconds = [](Clock::time_point since) {
        return std::chrono::duration<double>(Clock::now() - since).count();
    };
    auto reader = openPointCloud(inPath);
    const std::uint64_t declared = reader->info().pointCount;
    IncrementalMortonSorter sorter(reader->info(), options);
    ProgressLine progress;
    const auto readStart = Clock::now();
    ReadOptions readOptions;
    readOptions.batchPoints = options.batchPoints;
    const ReadSummary read = reader->read(
        [&](const PointBatch& batch) {
            sorter.add(batch);
            progress.update("reading", sorter.pointCount(), declared);
        },
        readOptions);
    const double readSeconds = seconds(readStart);

    const auto sortStart = Clock::now();
    OmsWriter writer;
    std::uint64_t written = 0;
    const int chunksUsed =
        sorter.sortAndEmit([&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
            if (written == 0) {
                writer.open(outPath, cloud.cube(), cloud.sourceOffset(), cloud.attributes(),
                            sorter.pointCount());
            }
            writer.append(cloud, begin, end);
            written += end - begin;
            progress.update("sorted and written", written, sorter.pointCount());
        });
    if (written == 0) {
        throw InputError(InputErrorKind::NoPoints, inPath, InputLocation::none(),
                         "no finite point to sort");
    }
    writer.finish();
    progress.finish();
    std::printf("sorted %llu points (%llu non-finite skipped) into %s: read %.3f s, first "
                "sorted batch %.3f s after reading, sort and write %.3f s, %d chunks, "
                "%d threads\n",
                static_cast<unsigned long long>(written),
                static_cast<unsigned long long>(read.skippedNonFinite), outPath.c_str(),
                readSeconds, sorter.firstRangeSeconds(), seconds(sortStart), chunksUsed, threads);
    return 0;
}

} // namespace

const Command& sortCommand() {
    static const Command command{
        "sort", "sort a cloud in Morton order into a sorted stream file (.oms)",
        "sort IN OUT.oms [--chunks K] [--threads T]",
        "Reads IN (PLY, LAS or XYZ), sorts its points by their level-21 Morton code in the\n"
        "cube of its bounding box (origin = min corner, edge = largest extent) and writes the\n"
        "sorted stream OUT.oms (docs/FORMATS.md) while sorted chunks come out. OUT is written\n"
        "to a temporary file and renamed at the end: a failed sort leaves no partial file.\n"
        "\n"
        "  --chunks K   sort chunks, 1..256 (default 32): more chunks give the first sorted\n"
        "               batch sooner after reading ends\n"
        "  --threads T  worker threads (default: all cores)\n"
        "\n"
        "Progress goes to stderr. Exit status: 0 ok, 1 input or output error, 2 usage error.\n",
        runSort};
    return command;
}

} // namespace omicron::cli
