// omicron-cli convert IN OUT: any supported cloud to PLY, LAS, XYZ or a .oms sorted stream,
// chosen by OUT's extension.
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/oms_reader.hpp"
#include "io/cloud_export.hpp"
#include "io/las/las_writer.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "io/xyz/xyz_writer.hpp"
#include "output_check.hpp"
#include "sort_to_oms.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace omicron::cli {

namespace {

struct WholeCloud {
    PointBatch points;
    CubeTransform cube;
    glm::dvec3 sourceOffset{0.0};
    std::vector<std::uint8_t> lasExtraBytesDescriptors; // of a LAS or LAZ input
    std::vector<std::uint8_t> lasProjectionRecords;
};

WholeCloud readWhole(const std::string& path) {
    WholeCloud whole;
    if (isOmsFile(path)) {
        OmsReader reader(path);
        reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
        const auto cloud = reader.cloud();
        cloud->copyRange(0, cloud->sortedEnd(), whole.points);
        whole.cube = cloud->cube();
        whole.sourceOffset = cloud->sourceOffset();
        return whole;
    }
    LoadedCloud loaded = loadPointCloud(path);
    whole.points = std::move(loaded.points);
    whole.cube = loaded.info.cube;
    whole.sourceOffset = loaded.info.sourceOffset;
    whole.lasExtraBytesDescriptors = std::move(loaded.info.lasExtraBytesDescriptors);
    whole.lasProjectionRecords = std::move(loaded.info.lasProjectionRecords);
    return whole;
}

// LAS stores integers: a millimetre step, or finer for a small cloud (at most 2^30 steps per
// cube edge), against the cube's origin, so every coordinate fits in int32.
// A cloud read from LAS or LAZ keeps every LAS field (LAS 1.4, see lasExportOptions).
LasWriteOptions lasOptions(const WholeCloud& whole) {
    LasWriteOptions options;
    if (whole.points.attributes.has(Attribute::Las)) {
        options = lasExportOptions(whole.points.attributes, whole.cube,
                                   whole.lasExtraBytesDescriptors, whole.lasProjectionRecords);
    }
    options.offset = whole.cube.origin;
    const double step = std::min(0.001, whole.cube.edge / double(1u << 30));
    options.scale = glm::dvec3(step);
    return options;
}

int runConvert(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, kMemoryOptionSpecs);
    if (parsed.help) {
        printCommandHelp(convertCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN and OUT, found " + std::to_string(parsed.positionals.size()) +
                         " arguments");
    }
    const std::string& inPath = parsed.positionals[0];
    const std::string& outPath = parsed.positionals[1];
    const std::string extension = lowerExtension(outPath);
    if (extension == ".oms") {
        if (isOmsFile(inPath)) {
            throw UsageError("IN is already a .oms sorted stream");
        }
        const MemoryOptions memory = memoryOptions(parsed, outPath);
        SortOptions options;
        options.memoryBudgetBytes = memory.budgetBytes;
        options.tempDir = memory.tempDir;
        options.previewPoints = 0; // nothing shows it
        sortToOms(inPath, outPath, options);
        std::printf("converted %s to the sorted stream %s\n", inPath.c_str(), outPath.c_str());
        return 0;
    }
    if (extension != ".ply" && extension != ".las" && extension != ".xyz" && extension != ".txt") {
        throw UsageError("OUT must end in .ply, .las, .xyz, .txt or .oms, found '" + outPath + "'");
    }
    checkOutputWritable(outPath);
    const WholeCloud whole = readWhole(inPath);
    if (extension == ".ply") {
        PlyWriteOptions options;
        options.offset = plyStorageOffset(whole.cube, whole.sourceOffset);
        options.comments.push_back("converted by omicron-cli from " + inPath);
        writePly(outPath, whole.points, whole.cube, options);
    } else if (extension == ".las") {
        writeLas(outPath, whole.points, whole.cube, lasOptions(whole));
    } else {
        writeXyz(outPath, whole.points, whole.cube);
    }
    std::printf("converted %zu points from %s to %s\n", whole.points.size(), inPath.c_str(),
                outPath.c_str());
    return 0;
}

} // namespace

const Command& convertCommand() {
    static const Command command{
        "convert", "convert a cloud to PLY, LAS, XYZ or a .oms sorted stream",
        "convert IN OUT [--memory-budget SIZE] [--temp-dir DIR]",
        "Reads IN (PLY, LAS, LAZ, XYZ text or .oms) and writes OUT in the format its extension\n"
        "names: .ply (binary little-endian, float coordinates against a 'comment offset'),\n"
        "LAS (.las, millimetre steps or finer: LAS 1.4 format 6, 7 or 8 with every LAS field\n"
        "and extra byte of a LAS or LAZ input, else LAS 1.2 format 3), XYZ text (.xyz, .txt) or a\n"
        "Morton-sorted stream (.oms, from a cloud that is not one already). Points keep\n"
        "their colour, normal and intensity where the output format has the field. OUT is\n"
        "replaced atomically.\n"
        "\n"
        "  --memory-budget SIZE, --temp-dir DIR\n"
        "               for .oms output, as for 'sort': a sort larger than the budget runs\n"
        "               on disk (default: OUT's folder) within the budget\n"
        "\n"
        "Exit status: 0 ok, 1 input or output error, 2 usage error, 130 interrupted.\n",
        runConvert};
    return command;
}

} // namespace omicron::cli
