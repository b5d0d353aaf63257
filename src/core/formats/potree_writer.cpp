#include "formats/potree_writer.hpp"

#include "formats/potree_additive.hpp"
#include "formats/potree_attributes.hpp"
#include "formats/potree_hierarchy.hpp"
#include "io/atomic_folder.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <span>
#include <string_view>
#include <vector>

namespace omicron {

namespace {

// What an existing folder may hold for an export to replace it: a Potree 2.0 export's files
// (log.txt is PotreeConverter's). Anything else is the user's, and is never deleted.
std::string refuseUnlessPotreeExport(const std::string& folder) {
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        const std::string name = entry.path().filename().string();
        if (name != "metadata.json" && name != "hierarchy.bin" && name != "octree.bin" &&
            name != "log.txt") {
            return "it holds '" + name + "', which is not part of a Potree export";
        }
    }
    return {};
}

std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.17g", value);
    return text;
}

std::string triple(const std::array<double, 3>& v) {
    std::string text("[");
    text.append(number(v[0])).append(", ").append(number(v[1])).append(", ");
    return text.append(number(v[2])).append("]");
}

std::string jsonEscape(const std::string& text) {
    std::string out;
    for (char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof(escaped), "\\u%04x", static_cast<unsigned char>(c));
            out += escaped;
        } else {
            out += c;
        }
    }
    return out;
}

struct Geometry {
    std::array<double, 3> boxMin;
    double edge;
    double scale;
};

std::string metadataJson(const PotreeExportOptions& options, const PotreeExportSummary& summary,
                         const PotreeHierarchyFile& hierarchy, const Geometry& geometry,
                         const PotreeRecordEncoder& encoder, int stepSize) {
    // Appended piece by piece: GCC 12's -Wrestrict misfires on "literal" + std::string.
    std::string json;
    const auto add = [&json](std::initializer_list<std::string_view> pieces) {
        for (std::string_view piece : pieces) {
            json.append(piece);
        }
    };
    std::string description("exported by omicron: ");
    description.append(std::to_string(summary.inputPoints)).append(" input points, ");
    description.append(std::to_string(summary.points)).append(" stored once each, ");
    description.append(std::to_string(summary.droppedPoints));
    description.append(" dropped by the paper's leaf collapse");
    const std::array<double, 3>& min = geometry.boxMin;
    const double edge = geometry.edge;
    add({"{\n  \"version\": \"2.0\",\n  \"name\": \"", jsonEscape(options.name), "\",\n"});
    add({"  \"description\": \"", jsonEscape(description), "\",\n"});
    add({"  \"points\": ", std::to_string(summary.points), ",\n  \"projection\": \"\",\n"});
    add({"  \"hierarchy\": {\n    \"firstChunkSize\": ", std::to_string(hierarchy.firstChunkSize),
         ",\n    \"stepSize\": ", std::to_string(stepSize),
         ",\n    \"depth\": ", std::to_string(hierarchy.depth), "\n  },\n"});
    add({"  \"offset\": ", triple(min),
         ",\n  \"scale\": ", triple({geometry.scale, geometry.scale, geometry.scale}),
         ",\n  \"spacing\": ", number(edge / 128.0), ",\n"});
    add({"  \"boundingBox\": {\n    \"min\": ", triple(min),
         ",\n    \"max\": ", triple({min[0] + edge, min[1] + edge, min[2] + edge}), "\n  },\n"});
    add({"  \"encoding\": \"DEFAULT\",\n  \"attributes\": ",
         encoder.attributesJson(geometry.scale, min, "    "), "\n}\n"});
    return json;
}

} // namespace

std::unique_ptr<AtomicFolder> openPotreeExportFolder(const std::string& folder) {
    return std::make_unique<AtomicFolder>(folder, refuseUnlessPotreeExport);
}

PotreeExportSummary exportPotree(const Hierarchy& hierarchy, const std::string& folder,
                                 const PotreeExportOptions& options) {
    const std::unique_ptr<AtomicFolder> target = openPotreeExportFolder(folder);
    return exportPotree(hierarchy, *target, options);
}

PotreeExportSummary exportPotree(const Hierarchy& hierarchy, AtomicFolder& target,
                                 const PotreeExportOptions& options) {
    const std::string& folder = target.targetPath();
    if (!hierarchy.publishedCut().complete || hierarchy.nodeCount(0) != 1) {
        throw OutputError(folder + ": only a complete hierarchy can be exported");
    }
    if (hierarchy.residency() != nullptr) {
        throw OutputError(folder +
                          ": the hierarchy's points are paged in on demand (a .omh file larger "
                          "than the memory budget); export the file with "
                          "'omicron-cli export-potree FILE.omh DIR' instead");
    }
    if (options.stepSize < 1) {
        throw OutputError(folder + ": the hierarchy step size must be at least 1");
    }
    const SortedCloud& cloud = hierarchy.cloud();
    const CubeTransform& cube = cloud.cube();
    const Geometry geometry{{cube.origin.x + cloud.sourceOffset().x,
                             cube.origin.y + cloud.sourceOffset().y,
                             cube.origin.z + cloud.sourceOffset().z},
                            cube.edge,
                            cube.edge / kPotreeStepsPerEdge};
    PotreeRecordEncoder encoder(cloud);
    const std::size_t recordBytes = encoder.recordBytes();

    std::uint64_t heldTotal = 0;
    std::vector<std::vector<PotreeNodePoints>> nodePoints;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        nodePoints.emplace_back(hierarchy.nodeCount(level));
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            heldTotal += hierarchy.node(level, i).pointCount;
        }
    }

    PotreeExportSummary summary;
    {
        AtomicFileWriter octree(target.file("octree.bin"));
        std::vector<std::uint8_t> records;
        std::uint64_t heldDone = 0;
        const auto writeNode = [&](int level, std::size_t index,
                                   std::span<const std::uint32_t> points) {
            PotreeNodePoints& stored = nodePoints[static_cast<std::size_t>(level)][index];
            stored.count = static_cast<std::uint32_t>(points.size());
            stored.byteOffset = octree.bytesWritten();
            records.resize(points.size() * recordBytes);
            for (std::size_t p = 0; p < points.size(); ++p) {
                encoder.encode(points[p], records.data() + p * recordBytes);
            }
            octree.write(records.data(), records.size());
            summary.points += points.size();
            heldDone += hierarchy.node(level, index).pointCount;
            if (options.onProgress) {
                options.onProgress(heldDone, heldTotal);
            }
            if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) {
                throw PotreeExportCancelled(folder);
            }
        };
        try {
            visitAdditiveNodes(hierarchy, writeNode);
        } catch (const NotNestedError& error) {
            throw OutputError(folder + ": cannot store each point once: " + error.what());
        }
        summary.octreeBytes = octree.bytesWritten();
        octree.commit();
    }

    const PotreeHierarchyFile layout =
        layoutPotreeHierarchy(hierarchy, nodePoints, recordBytes, options.stepSize);
    {
        AtomicFileWriter file(target.file("hierarchy.bin"));
        file.write(layout.bytes.data(), layout.bytes.size());
        file.commit();
    }
    summary.nodes = layout.nodes;
    summary.chunks = layout.chunks;
    summary.depth = layout.depth;
    // A node-order cloud (a loaded .omh) holds the parents' copies: its size is no input count.
    summary.inputPoints = options.inputPoints > 0               ? options.inputPoints
                          : cloud.order() == CloudOrder::Morton ? cloud.sortedEnd()
                                                                : summary.points;
    summary.droppedPoints =
        summary.inputPoints > summary.points ? summary.inputPoints - summary.points : 0;
    const double storeError =
        cloud.storage() == PointStorage::Packed ? std::ldexp(1.0, -22) : std::ldexp(1.0, -25);
    summary.positionTolerance = cube.edge * (storeError + std::ldexp(1.0, -30));

    AtomicFileWriter metadata(target.file("metadata.json"));
    metadata.write(metadataJson(options, summary, layout, geometry, encoder, options.stepSize));
    metadata.commit();
    target.commit();
    return summary;
}

} // namespace omicron
