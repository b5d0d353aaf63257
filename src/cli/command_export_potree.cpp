// omicron-cli export-potree IN DIR: any cloud, sorted stream or saved hierarchy in the Potree
// 2.0 format, for Potree and the tools that read PotreeConverter 2's output. A cloud or .oms
// is built first, by the same pipeline as `build`; a .omh is loaded whole.
#include "build_args.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/omh_reader.hpp"
#include "formats/potree_writer.hpp"
#include "interrupt.hpp"
#include "json_writer.hpp"
#include "pipeline/build_pipeline.hpp"
#include "progress_line.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <tbb/global_control.h>
#include <thread>

namespace omicron::cli {

namespace {

struct Source {
    std::shared_ptr<const Hierarchy> hierarchy;
    std::uint64_t inputPoints = 0; // 0: the hierarchy's cloud says (a build)
};

Source loadSavedHierarchy(const std::string& path, const ParsedArgs& parsed) {
    for (const OptionSpec& spec : kBuildOptionSpecs) {
        if (parsed.value(spec.name)) {
            throw UsageError("--" + spec.name + " builds a hierarchy, but " + path +
                             " is a saved one: it is exported as it was built");
        }
    }
    OmhReader reader(path);
    const auto hierarchy = reader.hierarchy();
    reader.load({}, &watchInterrupts());
    throwIfInterrupted();
    return {hierarchy, reader.header().build.inputPoints};
}

Source buildHierarchy(const std::string& path, const ParsedArgs& parsed,
                      const std::string& folder) {
    const BuildArgs build = buildArgs(parsed);
    tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(build.threads));
    const MemoryOptions memory = memoryOptions(parsed, folder);
    BuildPipeline pipeline;
    runInterruptibly(pipeline, path,
                     {build.options, build.sortChunks, build.storage, memory.budgetBytes,
                      memory.tempDir,
                      /*preview=*/false});
    return {pipeline.hierarchy(), 0};
}

// Test hook, not a user option: with OMICRON_TEST_PAUSE_POTREE_EXPORT=1 in the environment,
// the export stops after its first node for up to a minute (until Ctrl+C), so a test can
// interrupt it half-way and check that nothing is left behind.
void pauseForTest() {
    const char* pause = std::getenv("OMICRON_TEST_PAUSE_POTREE_EXPORT");
    if (pause == nullptr || std::string(pause) != "1") {
        return;
    }
    std::fprintf(stderr, "omicron-cli: export paused after the first node (test hook)\n");
    std::fflush(stderr);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!watchInterrupts().load() && std::chrono::steady_clock::now() < until) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

void printJson(const PotreeExportSummary& s, const std::string& folder) {
    JsonWriter json;
    json.beginObject();
    json.key("folder").value(folder);
    json.key("points").value(s.points);
    json.key("input_points").value(s.inputPoints);
    json.key("dropped_points").value(s.droppedPoints);
    json.key("nodes").value(s.nodes);
    json.key("chunks").value(s.chunks);
    json.key("depth").value(static_cast<std::uint64_t>(s.depth));
    json.key("octree_bytes").value(s.octreeBytes);
    json.key("position_tolerance").value(s.positionTolerance);
    json.endObject();
    std::printf("%s\n", json.text().c_str());
}

void printText(const PotreeExportSummary& s, const std::string& in, const std::string& folder) {
    std::printf("exported:   %s -> %s (Potree 2.0, DEFAULT encoding)\n", in.c_str(),
                folder.c_str());
    std::printf("points:     %llu of %llu input points, each stored once (%llu dropped by "
                "leaf collapse)\n",
                static_cast<unsigned long long>(s.points),
                static_cast<unsigned long long>(s.inputPoints),
                static_cast<unsigned long long>(s.droppedPoints));
    std::printf("nodes:      %llu in %llu hierarchy chunks, depth %d\n",
                static_cast<unsigned long long>(s.nodes), static_cast<unsigned long long>(s.chunks),
                s.depth);
    std::printf("positions:  within %.3g of the input (source units)\n", s.positionTolerance);
}

int runExportPotree(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(
        args, withOptions(withOptions(kBuildOptionSpecs, {{"json", false}}), kMemoryOptionSpecs));
    if (parsed.help) {
        printCommandHelp(exportPotreeCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN and DIR, found " + std::to_string(parsed.positionals.size()) +
                         " arguments");
    }
    const std::string& inPath = parsed.positionals[0];
    const std::string& folder = parsed.positionals[1];
    // The target is checked and its temporary folder made before the work: a folder that may
    // not be replaced fails now, not after a build.
    const std::unique_ptr<AtomicFolder> target = openPotreeExportFolder(folder);
    const Source source = isOmhFile(inPath) ? loadSavedHierarchy(inPath, parsed)
                                            : buildHierarchy(inPath, parsed, folder);

    PotreeExportOptions options;
    options.name = std::filesystem::path(inPath).stem().string();
    options.inputPoints = source.inputPoints;
    options.cancel = &watchInterrupts();
    ProgressLine progress;
    bool first = true;
    options.onProgress = [&](std::uint64_t done, std::uint64_t total) {
        progress.update("writing the Potree octree (hierarchy records)", done, total);
        if (first) {
            first = false;
            pauseForTest();
        }
    };
    PotreeExportSummary summary;
    try {
        summary = exportPotree(*source.hierarchy, *target, options);
    } catch (const PotreeExportCancelled&) {
        progress.finish();
        throw Interrupted();
    }
    progress.finish();
    if (parsed.flag("json")) {
        printJson(summary, folder);
    } else {
        printText(summary, inPath, folder);
    }
    return 0;
}

} // namespace

const Command& exportPotreeCommand() {
    static const Command command{
        "export-potree", "write any cloud or a saved hierarchy in the Potree 2.0 format",
        "export-potree IN DIR [--depth 7] [--ratio 0.2] [--collapse off|lossless|paper]\n"
        "                     [--worklist N] [--threads T] [--chunks K] [--store exact|packed]\n"
        "                     [--memory-budget SIZE] [--temp-dir DIR] [--json]",
        "IN is a cloud (PLY, LAS, XYZ) or a sorted stream (.oms), whose hierarchy is built\n"
        "first exactly as 'omicron-cli build' builds it (the build options are the same, see\n"
        "'omicron-cli build --help'), or a saved hierarchy (.omh), loaded as it was built.\n"
        "\n"
        "Writes DIR/metadata.json, DIR/hierarchy.bin and DIR/octree.bin in the Potree 2.0\n"
        "format, uncompressed (\"DEFAULT\" encoding), as Potree's loaders read them. The octree\n"
        "is additive like PotreeConverter's: every input point is stored once, in the\n"
        "shallowest node that holds it, so metadata.json's \"points\" is the input count (less\n"
        "the points a paper leaf collapse dropped: the output says how many). Bounding box,\n"
        "spacing (edge / 128) and offset as PotreeConverter 2 writes them; positions as int32\n"
        "in 2^30 steps of the cube's edge; rgb (uint16) and intensity (uint16) when present.\n"
        "\n"
        "The folder is written under a temporary name beside DIR and renamed into place when\n"
        "complete: an error or Ctrl+C leaves DIR as it was. An existing DIR is replaced only\n"
        "when it is empty or holds nothing but a Potree export; that is checked (and the\n"
        "temporary folder made) before the input is read, so a refusal costs no build.\n"
        "\n"
        "  --json             one JSON object: folder, points, input_points, dropped_points,\n"
        "                     nodes, chunks, depth, octree_bytes, position_tolerance (how far\n"
        "                     an exported position may lie from its input point)\n"
        "\n"
        "Exit status: 0 ok, 1 input or output error, 2 usage error, 130 interrupted.\n",
        runExportPotree};
    return command;
}

} // namespace omicron::cli
