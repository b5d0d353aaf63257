// omicron-cli tile IN OUT --copies N: a big test cloud made from a real one, N translated
// copies side by side, streamed so that memory stays constant whatever N (a billion points
// from autzen_south's 4.8 million in a few hundred megabytes of buffers, not 15 GB).
#include "cli_args.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "io/las/las_writer.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "progress_line.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <variant>

namespace omicron::cli {

namespace {

constexpr std::uint64_t kMaxCopies = 1'000'000;

// Copy k of n sits at column k % columns, row k / columns of a near-square grid, shifted by
// whole extents (plus the gap) in x and y, so copies never overlap and the result reads like
// one large survey.
struct TileGrid {
    std::uint64_t columns = 1;
    glm::dvec3 step{0.0};

    TileGrid(std::uint64_t copies, const Bounds& bounds, double gap) {
        columns = static_cast<std::uint64_t>(std::ceil(std::sqrt(double(copies))));
        const glm::dvec3 extent = bounds.extent();
        step = glm::dvec3(extent.x + gap, extent.y + gap, 0.0);
    }
    glm::dvec3 shift(std::uint64_t copy) const {
        return {double(copy % columns) * step.x, double(copy / columns) * step.y, 0.0};
    }
    Bounds bounds(const Bounds& one, std::uint64_t copies) const {
        const std::uint64_t rows = (copies + columns - 1) / columns;
        const std::uint64_t usedColumns = std::min(copies, columns);
        Bounds all = one;
        all.extend(one.max +
                   glm::dvec3(double(usedColumns - 1) * step.x, double(rows - 1) * step.y, 0.0));
        return all;
    }
};

// LAS records have no normals; every other attribute (the LAS fields of a LAS input) stays.
AttributeSet withoutNormals(AttributeSet attributes) {
    return AttributeSet::fromBits(attributes.bits() & ~static_cast<std::uint8_t>(Attribute::Normal),
                                  attributes.extraBytes());
}

using TileWriter = std::variant<std::unique_ptr<PlyStreamWriter>, std::unique_ptr<LasStreamWriter>>;

TileWriter openWriter(const std::string& inPath, const std::string& outPath,
                      const std::string& extension, std::uint64_t points, AttributeSet attributes,
                      const CloudInfo& info, const Bounds& all) {
    const CubeTransform outCube = CubeTransform::fromBounds(all);
    if (extension == ".ply") {
        PlyWriteOptions options;
        options.offset = plyStorageOffset(outCube, info.sourceOffset);
        options.comments.push_back("tiled by omicron-cli from " + inPath);
        return std::make_unique<PlyStreamWriter>(outPath, points, attributes, options);
    }
    // Millimetre steps (finer for a small cloud) against the tiled cloud's origin, so every
    // coordinate fits LAS's int32; LAS 1.4 once the count passes 1.2's 32-bit field.
    LasWriteOptions options;
    options.offset = glm::floor(outCube.origin);
    options.scale = glm::dvec3(std::min(0.001, outCube.edge / double(1u << 30)));
    if (points > std::numeric_limits<std::uint32_t>::max()) {
        options.versionMinor = 4;
        options.pointFormat = 7;
    }
    return std::make_unique<LasStreamWriter>(outPath, points, withoutNormals(attributes), options);
}

int runTile(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, {{"copies", true}, {"gap", true}});
    if (parsed.help) {
        printCommandHelp(tileCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN and OUT, found " + std::to_string(parsed.positionals.size()) +
                         " arguments");
    }
    const std::string& inPath = parsed.positionals[0];
    const std::string& outPath = parsed.positionals[1];
    const std::string extension = lowerExtension(outPath);
    if (extension != ".ply" && extension != ".las") {
        throw UsageError("OUT must end in .ply or .las, found '" + outPath + "'");
    }
    const auto copiesText = parsed.value("copies");
    if (!copiesText) {
        throw UsageError("--copies N is required");
    }
    const std::uint64_t copies = parseInteger(*copiesText, "copies", 1, kMaxCopies);
    double gap = 0.0;
    if (const auto gapText = parsed.value("gap")) {
        char* end = nullptr;
        gap = std::strtod(gapText->c_str(), &end);
        if (gapText->empty() || *end != '\0' || !std::isfinite(gap) || gap < 0.0) {
            throw UsageError("bad number for --gap: '" + *gapText +
                             "' (a distance >= 0 in the file's units)");
        }
    }

    const std::atomic<bool>& interrupted = watchInterrupts();
    ReadOptions readOptions;
    readOptions.cancel = &interrupted;
    OpenOptions openOptions;
    openOptions.cancel = &interrupted;

    // A first read counts the points a reader delivers (non-finite ones are skipped), since
    // the output's header states its count before the first record.
    std::uint64_t perCopy = 0;
    CloudInfo info;
    {
        auto reader = openPointCloud(inPath, openOptions);
        info = reader->info();
        const ReadSummary summary = reader->read([](const PointBatch&) {}, readOptions);
        throwIfInterrupted();
        perCopy = summary.pointsDelivered;
    }
    if (perCopy > std::numeric_limits<std::uint64_t>::max() / copies) {
        throw UsageError(std::to_string(copies) + " copies of " + std::to_string(perCopy) +
                         " points overflow a 64-bit count");
    }
    const std::uint64_t total = perCopy * copies;
    const TileGrid grid(copies, info.sourceBounds, gap);
    const Bounds all = grid.bounds(info.sourceBounds, copies);
    TileWriter writer = openWriter(inPath, outPath, extension, total, info.attributes, info, all);

    // Later reads know the bounds: no pre-pass, one sequential read per copy.
    openOptions.knownBounds = info.sourceBounds;
    ProgressLine progress;
    PointBatch lasBatch;
    for (std::uint64_t copy = 0; copy < copies; ++copy) {
        auto reader = openPointCloud(inPath, openOptions);
        CubeTransform placed = reader->info().cube;
        placed.origin += grid.shift(copy);
        reader->read(
            [&](const PointBatch& batch) {
                if (auto* ply = std::get_if<std::unique_ptr<PlyStreamWriter>>(&writer)) {
                    (*ply)->append(batch, placed);
                    return;
                }
                const PointBatch* points = &batch;
                if (batch.attributes.has(Attribute::Normal)) {
                    lasBatch = batch;
                    lasBatch.normals.clear();
                    lasBatch.attributes = withoutNormals(batch.attributes);
                    points = &lasBatch;
                }
                std::get<std::unique_ptr<LasStreamWriter>>(writer)->append(*points, placed);
            },
            readOptions);
        throwIfInterrupted();
        progress.update("tiling", (copy + 1) * perCopy, total);
    }
    progress.finish();
    std::visit([](auto& w) { w->finish(); }, writer);
    std::printf("wrote %llu copies of %llu points (%llu points) to %s\n",
                static_cast<unsigned long long>(copies), static_cast<unsigned long long>(perCopy),
                static_cast<unsigned long long>(total), outPath.c_str());
    return 0;
}

} // namespace

const Command& tileCommand() {
    static const Command command{
        "tile", "N translated copies of a cloud side by side (big test clouds)",
        "tile IN OUT --copies N [--gap G]",
        "Writes N copies of IN side by side to OUT, streaming: memory stays constant whatever\n"
        "N, so anyone can make a billion-point cloud from a real scan, e.g.\n"
        "  omicron-cli tile ../shared/data/autzen_south.ply big.ply --copies 207\n"
        "Copies fill a near-square grid (ceil(sqrt N) columns along x, rows along y), each\n"
        "shifted by whole extents of IN plus G; each keeps IN's point order and attributes.\n"
        "IN is read once to count its points, then once per copy.\n\n"
        "  IN           any cloud (PLY, LAS, LAZ, XYZ)\n"
        "  OUT          .ply (binary float, against an offset comment) or .las (LAS 1.2\n"
        "               format 3, LAS 1.4 format 7 past 2^32 points; 1 mm steps; no normals)\n"
        "  --copies N   1 to 1000000\n"
        "  --gap G      space between copies in IN's units (default 0)\n\n"
        "OUT is written under a temporary name and renamed when complete: an error or Ctrl+C\n"
        "leaves no partial file. Make sure the disk holds N times IN's size.\n",
        runTile};
    return command;
}

} // namespace omicron::cli
