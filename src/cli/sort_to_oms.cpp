#include "sort_to_oms.hpp"

#include "formats/oms_writer.hpp"
#include "interrupt.hpp"
#include "io/input_error.hpp"
#include "io/point_reader.hpp"
#include "output_check.hpp"
#include "progress_line.hpp"

#include <chrono>

namespace omicron::cli {

SortToOmsResult sortToOms(const std::string& inPath, const std::string& outPath,
                          SortOptions options) {
    using Clock = std::chrono::steady_clock;
    const auto seconds = [](Clock::time_point since) {
        return std::chrono::duration<double>(Clock::now() - since).count();
    };
    checkOutputWritable(outPath); // before the input is read, not after the sort
    const std::atomic<bool>& interrupted = watchInterrupts();
    options.cancel = &interrupted;
    OpenOptions openOptions;
    openOptions.cancel = &interrupted;
    auto reader = openPointCloud(inPath, openOptions);
    const std::uint64_t declared = reader->info().pointCount;
    IncrementalMortonSorter sorter(reader->info(), options);
    SortToOmsResult result;
    result.spilled = sorter.spills();
    result.scratchParent = options.tempDir;

    ProgressLine progress;
    const auto readStart = Clock::now();
    ReadOptions readOptions;
    readOptions.batchPoints = options.batchPoints;
    readOptions.cancel = &interrupted;
    const ReadSummary read = reader->read(
        [&](const PointBatch& batch) {
            sorter.add(batch);
            progress.update(sorter.spills() ? "reading into sorted runs" : "reading",
                            sorter.pointCount(), declared);
        },
        readOptions);
    throwIfInterrupted();
    result.readSeconds = seconds(readStart);
    result.skippedNonFinite = read.skippedNonFinite;
    if (sorter.pointCount() == 0) {
        throw InputError(InputErrorKind::NoPoints, inPath, InputLocation::none(),
                         "no finite point to sort");
    }

    const auto sortStart = Clock::now();
    OmsWriter writer;
    const auto openOnce = [&](const SortedCloud& cloud) {
        if (result.written == 0) {
            result.firstSortedSeconds = seconds(sortStart);
            // A column the sort kept uniform (an in-memory sort) goes in the header once.
            writer.open(outPath, cloud.cube(), cloud.sourceOffset(), cloud.attributes(),
                        sorter.pointCount(), oms::uniformColumnsOf(cloud));
        }
    };
    if (sorter.spills()) {
        sorter.emitSortedBatches([&](const PointBatch& sorted) {
            // The cloud only gives the cube and the uniform columns; it stays empty.
            openOnce(*sorter.cloud());
            writer.append(sorted);
            result.written += sorted.size();
            progress.update("merging runs into the sorted stream", result.written,
                            sorter.pointCount());
        });
        result.chunks = static_cast<int>(sorter.runCount());
    } else {
        result.chunks =
            sorter.sortAndEmit([&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
                openOnce(cloud);
                writer.append(cloud, begin, end);
                result.written += end - begin;
                progress.update("sorted and written", result.written, sorter.pointCount());
            });
    }
    throwIfInterrupted();
    writer.finish();
    progress.finish();
    result.sortSeconds = seconds(sortStart);
    return result;
}

} // namespace omicron::cli
