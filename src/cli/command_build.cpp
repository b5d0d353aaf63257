// omicron-cli build: pipeline 1 (unsorted cloud -> sorter -> builder) or pipeline 2 (.oms ->
// builder), then the build statistics as text or JSON.
#include "build_args.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/omh_column_stream.hpp"
#include "formats/omh_writer.hpp"
#include "interrupt.hpp"
#include "io/atomic_file_writer.hpp"
#include "json_writer.hpp"
#include "levels_json.hpp"
#include "pipeline/build_pipeline.hpp"
#include "points/huge_page_buffer.hpp"
#include "points/huge_page_policy.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <thread>

namespace omicron::cli {

namespace {

// The page size the cloud's big arrays asked for (points/huge_page_policy.hpp).
const char* pagesInUse() {
    return hugePagesPayOff() ? "huge" : "small";
}

struct SavedFile {
    std::string path; // empty without --save
    std::uint64_t bytes = 0;
    std::uint64_t streamedBytes = 0; // the deepest level's columns written during the build
};

// --save-version, and a test hook (not a user option): with OMICRON_TEST_PAUSE_SAVE_AFTER_LEVEL=N
// in the environment, a save stops for a minute after level N's points went to the temporary file,
// so a test can kill the process half-way and check that the previous file survives.
OmhWriteOptions saveOptions(const ParsedArgs& parsed) {
    OmhWriteOptions options;
    if (const auto version = parsed.value("save-version")) {
        options.formatVersion =
            static_cast<std::uint32_t>(parseInteger(*version, "save-version", 2, omh::kVersion));
    }
    if (const char* pauseLevel = std::getenv("OMICRON_TEST_PAUSE_SAVE_AFTER_LEVEL")) {
        const int level = std::atoi(pauseLevel);
        options.afterLevel = [level](int written) {
            if (written == level) {
                std::fprintf(stderr, "omicron-cli: save paused after level %d (test hook)\n",
                             level);
                std::fflush(stderr);
                std::this_thread::sleep_for(std::chrono::seconds(60));
            }
        };
    }
    return options;
}

void printJson(const PipelineResult& run, const BuildOptions& options, const SavedFile& saved) {
    const BuildStatistics& s = run.stats;
    JsonWriter json;
    json.beginObject();
    json.key("pipeline").value(run.pipeline);
    json.key("depth").value(static_cast<std::uint64_t>(options.maxLevel));
    json.key("ratio").value(options.ratio);
    json.key("worklist").value(static_cast<std::uint64_t>(options.worklistSize));
    json.key("collapse").value(toString(options.collapse));
    json.key("points_in").value(s.inputPoints);
    json.key("dropped_points").value(s.droppedPoints);
    json.key("collapsed_leaves").value(s.collapsedLeaves);
    json.key("placeholders_created").value(s.placeholdersCreated);
    json.key("placeholders_substituted").value(s.placeholdersSubstituted);
    writeLevelsJson(json, s.levels);
    json.key("nodes").value(s.totalNodes());
    json.key("creation_s").value(s.creationSeconds);
    json.key("read_s").value(run.readSeconds);
    json.key("sort_s").value(run.sortSeconds);
    json.key("sort_runs").value(static_cast<std::uint64_t>(run.sortRuns));
    json.key("recycled_bytes").value(run.recycledBytes);
    json.key("bytes_resident").value(static_cast<std::uint64_t>(s.bytesResident()));
    json.key("point_storage").value(toString(s.pointStorage));
    json.key("pages").value(pagesInUse());
    json.key("cloud_bytes").value(static_cast<std::uint64_t>(s.cloudBytes));
    json.key("hierarchy_bytes")
        .value(static_cast<std::uint64_t>(s.nodeBytes + s.sampleBytes + s.splatBytes));
    json.key("milestones_s").beginArray();
    for (double seconds : s.milestonesSeconds) {
        json.value(seconds);
    }
    json.endArray();
    json.key("fix_passes").value(s.fixPasses);
    json.key("duplicate_parents_merged").value(s.duplicateParentsMerged);
    json.key("complete").value(s.complete);
    if (!saved.path.empty()) {
        json.key("saved").value(saved.path);
        json.key("saved_bytes").value(saved.bytes);
        json.key("saved_streamed_bytes").value(saved.streamedBytes);
    }
    json.endObject();
    std::printf("%s\n", json.text().c_str());
}

// The kernel frees an exiting process's pages on one core: 75 ms of `build --save`'s 1.5 s on
// 24.2 M LAS points here, with the other core idle. MADV_DONTNEED takes the address space's
// lock for reading only, so slices of the cloud's arrays given back on every core free
// together (about 40 ms on two cores), and what is left to unmap is cheap. The cloud reads as
// zeros afterwards (a file-backed one from its file): call it when nothing reads it again.
void dropCloudPagesOnAllCores(const SortedCloud& cloud) {
    const auto drop = [](const void* data, std::size_t size) {
        constexpr std::size_t kSliceBytes = std::size_t{8} << 20;
        const auto* bytes = static_cast<const std::uint8_t*>(data);
        tbb::parallel_for(std::size_t{0}, (size + kSliceBytes - 1) / kSliceBytes,
                          [&](std::size_t slice) {
                              const std::size_t begin = slice * kSliceBytes;
                              releasePages(bytes + begin, std::min(kSliceBytes, size - begin));
                          });
    };
    drop(cloud.positions().data(), cloud.positions().size_bytes());
    drop(cloud.normals().data(), cloud.normals().size_bytes());
    drop(cloud.colors().data(), cloud.colors().size_bytes());
    // A uniform column (stride 0) holds one value: nothing worth giving back.
    drop(cloud.intensities().data,
         cloud.capacity() * cloud.intensities().stride * sizeof(std::uint16_t));
    drop(cloud.lasColumn().data, cloud.capacity() * cloud.lasColumn().stride);
}

void printText(const PipelineResult& run, const BuildOptions& options, const SavedFile& saved) {
    const BuildStatistics& s = run.stats;
    std::printf("pipeline:    %s\n", run.pipeline.c_str());
    std::printf("parameters:  depth %d, ratio %.3g, worklist %zu, leaf collapse %s\n",
                options.maxLevel, options.ratio, options.worklistSize, toString(options.collapse));
    std::printf("points:      %llu in, %llu dropped by leaf collapse, %llu leaves collapsed\n",
                static_cast<unsigned long long>(s.inputPoints),
                static_cast<unsigned long long>(s.droppedPoints),
                static_cast<unsigned long long>(s.collapsedLeaves));
    std::printf("level  nodes        leaves       points\n");
    for (std::size_t level = 0; level < s.levels.size(); ++level) {
        std::printf("%5zu  %-11llu  %-11llu  %llu\n", level,
                    static_cast<unsigned long long>(s.levels[level].nodes),
                    static_cast<unsigned long long>(s.levels[level].leaves),
                    static_cast<unsigned long long>(s.levels[level].points));
    }
    std::printf("time:        read %.3f s, sort %.3f s, hierarchy complete %.3f s after start\n",
                run.readSeconds, run.sortSeconds, s.creationSeconds);
    if (run.sortRuns > 0) {
        std::printf("sort:        beyond the memory budget: %zu sorted runs on disk, merged\n",
                    run.sortRuns);
    }
    std::printf("memory:      %.1f MiB resident (%.1f bytes per input point), %s point store on "
                "%s pages\n",
                s.bytesResident() / 1048576.0,
                s.inputPoints ? double(s.bytesResident()) / double(s.inputPoints) : 0.0,
                toString(s.pointStorage), pagesInUse());
    if (!saved.path.empty()) {
        std::printf("saved:       %s (%llu bytes)\n", saved.path.c_str(),
                    static_cast<unsigned long long>(saved.bytes));
    }
}

int runBuild(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(
        args, withOptions(withOptions(kBuildOptionSpecs,
                                      {{"json", false}, {"save", true}, {"save-version", true}}),
                          kMemoryOptionSpecs));
    if (parsed.help) {
        printCommandHelp(buildCommand());
        return 0;
    }
    if (parsed.positionals.size() != 1) {
        throw UsageError("expected one input file, found " +
                         std::to_string(parsed.positionals.size()) + " arguments");
    }
    const BuildArgs build = buildArgs(parsed);
    const BuildOptions& options = build.options;
    tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(build.threads));

    const std::string& path = parsed.positionals[0];
    const std::optional<std::string> savePath = parsed.value("save");
    if (parsed.value("save-version") && !savePath) {
        throw UsageError("--save-version needs --save");
    }
    const OmhWriteOptions writeOptions = saveOptions(parsed); // a bad version before the build
    const MemoryOptions memory = memoryOptions(parsed, savePath.value_or(""));
    // The save's temporary file is made now: a target that cannot be written fails before the
    // build, not after it (an hour, for a billion points).
    std::optional<AtomicFileWriter> saveFile;
    BuildPipeline pipeline;
    // Where every leaf will be at the deepest level, a version 4 save's deepest level (the
    // sorted cloud's arrays) goes to the file while the hierarchy is built
    // (formats/omh_column_stream.hpp).
    std::unique_ptr<OmhColumnStream> columnStream;
    if (savePath) {
        saveFile.emplace(*savePath);
        if (options.collapse == LeafCollapse::Off &&
            writeOptions.formatVersion >= omh::kFirstVersionWithDeepestColumns) {
            columnStream = std::make_unique<OmhColumnStream>(
                *saveFile, options.maxLevel, [&pipeline] { return pipeline.sortedCloud(); });
        }
    }
    const PipelineResult run = runInterruptibly(pipeline, path,
                                                {options, build.sortChunks, build.storage,
                                                 memory.budgetBytes, memory.tempDir,
                                                 /*preview=*/false});
    SavedFile saved;
    if (saveFile) { // the finished hierarchy, pipeline 3's input
        const OmhStreamedColumns streamed =
            columnStream ? columnStream->finish() : OmhStreamedColumns{};
        OmhWriteOptions save = writeOptions;
        save.streamedColumns = columnStream ? &streamed : nullptr;
        const OmhSaveReport report =
            writeOmh(*saveFile, *pipeline.hierarchy(), omhBuildInfo(options, run.stats), save);
        saved = {*savePath, std::filesystem::file_size(*savePath), report.streamedBytesUsed};
    }
    if (parsed.flag("json")) {
        printJson(run, options, saved);
    } else {
        printText(run, options, saved);
    }
    if (const auto hierarchy = pipeline.hierarchy()) { // last: nothing reads it after this
        dropCloudPagesOnAllCores(hierarchy->cloud());
    }
    return 0;
}

} // namespace

const Command& buildCommand() {
    static const Command command{
        "build", "build the OMiCroN hierarchy of a cloud and print its statistics",
        "build IN [--depth 7] [--ratio 0.2] [--worklist N] [--collapse off|lossless|paper]\n"
        "                   [--threads T] [--chunks K] [--store exact|packed] [--save OUT.omh]\n"
        "                   [--save-version 2|3|4] [--memory-budget SIZE] [--temp-dir DIR] "
        "[--json]",
        "Builds the octree bottom-up with oblique hierarchy cuts while the input streams in:\n"
        "an unsorted cloud (PLY, LAS, LAZ, XYZ) goes through the incremental Morton sorter first\n"
        "(pipeline 1), a sorted stream (.oms) feeds the builder directly (pipeline 2).\n"
        "\n"
        "  --depth D          hierarchy depth l_max, 1..21 (default 7)\n"
        "  --ratio R          parent points / children points, (0, 1] (default 0.2)\n"
        "  --worklist N       nodes per parallel work item (default 32)\n"
        "  --collapse MODE    off (default), lossless (a leaf without siblings merges into its\n"
        "                     parent) or paper (the parent keeps only its sample; the dropped\n"
        "                     points are counted)\n"
        "  --threads T        worker threads (default: all cores)\n"
        "  --chunks K         sort chunks for unsorted input, 1..256 (default 32)\n"
        "  --store MODE       exact (default: positions and colours as read) or packed\n"
        "                     (positions quantised to the level-21 grid, at most half a\n"
        "                     cell = 2^-22 of the cube's edge off, and colours, bit-packed\n"
        "                     per 64 points: about half the memory)\n"
        "  --save OUT.omh     save the finished hierarchy as a .omh file (written to a\n"
        "                     temporary file and renamed: an interrupted save leaves OUT as\n"
        "                     it was; the temporary is made before the build, so a target\n"
        "                     that cannot be written fails at once); 'info OUT.omh' prints\n"
        "                     the same per-level counts\n"
        "  --save-version V   the .omh format version: 4 (default: the deepest level as\n"
        "                     columns before the node table, written while the hierarchy\n"
        "                     is built), 3 (the same bytes as records in level order, for\n"
        "                     omicron builds that read up to version 3) or 2 (splat\n"
        "                     attributes stored for every point, 6 bytes more a point\n"
        "                     without normals, 2 with; for builds that read only version 2)\n"
        "  --memory-budget SIZE\n"
        "                     what the sort may keep resident, e.g. 512M or 4G (default: half\n"
        "                     of physical memory); a bigger sort runs on disk and its runs are\n"
        "                     merged into the cloud, which stays resident for the builder\n"
        "  --temp-dir DIR     where sorted runs go (default: OUT.omh's folder with --save,\n"
        "                     else $TMPDIR or /tmp); removed on success, error and Ctrl+C\n"
        "  --json             one JSON object: points_in, levels [{level, nodes, leaves,\n"
        "                     points}], creation_s, read_s, sort_s, sort_runs (0: sorted\n"
        "                     in memory), recycled_bytes (input pages the sort moved into\n"
        "                     the sorted cloud), bytes_resident\n"
        "                     (cloud_bytes + hierarchy_bytes), point_storage, pages (huge\n"
        "                     or small: which the big arrays asked for, see README)\n"
        "                     milestones_s (time at 10 %, 20 %, ... of the points inserted),\n"
        "                     saved, saved_bytes and saved_streamed_bytes (of them, the\n"
        "                     deepest level's written during the build) with --save\n"
        "\n"
        "Exit status: 0 ok, 1 input or output error, 2 usage error, 130 interrupted.\n",
        runBuild};
    return command;
}

} // namespace omicron::cli
