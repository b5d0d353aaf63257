#include "omh_info.hpp"

#include "formats/omh_reader.hpp"
#include "json_writer.hpp"
#include "levels_json.hpp"
#include "points/attribute_statistics.hpp"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace omicron::cli {

namespace {

// The columns stored once in the header (version 2) instead of in every record.
std::vector<std::string> uniformColumnNames(const omh::Header& h) {
    std::vector<std::string> names;
    if ((h.uniformColumns & omh::kUniformIntensityBit) != 0) {
        names.push_back("intensity " + std::to_string(h.uniformIntensity));
    }
    if ((h.uniformColumns & omh::kUniformLasBit) != 0) {
        names.emplace_back("LAS record");
    }
    return names;
}

void writeVector(JsonWriter& json, const glm::dvec3& v) {
    json.beginArray().value(v.x).value(v.y).value(v.z).endArray();
}

// Points whose splat attributes the file stores: all before version 3, then the sparse nodes'.
std::uint64_t storedSplatPoints(const omh::Header& h) {
    if (h.splatsInRecords()) {
        return h.totalPoints;
    }
    std::uint64_t points = 0;
    for (const omh::LevelEntry& level : h.levels) {
        points += level.sparsePoints;
    }
    return points;
}

void printJson(const omh::Header& h, bool verified) {
    JsonWriter json;
    json.beginObject();
    json.key("path").value(h.path);
    json.key("format").value("OMH hierarchy");
    json.key("version").value(std::uint64_t{h.version});
    json.key("file_bytes").value(h.fileBytes);
    json.key("depth").value(static_cast<std::uint64_t>(h.build.maxLevel));
    json.key("ratio").value(h.build.ratio);
    json.key("collapse").value(toString(h.build.collapse));
    json.key("points_in").value(h.build.inputPoints);
    json.key("dropped_points").value(h.build.droppedPoints);
    json.key("collapsed_leaves").value(h.build.collapsedLeaves);
    json.key("attributes").beginArray();
    for (const std::string& name : attributeNames(h.attributes)) {
        json.value(name);
    }
    json.endArray();
    json.key("estimated_normals").value(h.estimatedNormals);
    json.key("record_bytes").value(static_cast<std::uint64_t>(h.recordBytes));
    json.key("uniform_columns").beginArray();
    for (const std::string& name : uniformColumnNames(h)) {
        json.value(name);
    }
    json.endArray();
    json.key("offset");
    writeVector(json, h.sourceOffset);
    json.key("cube").beginObject();
    json.key("origin");
    writeVector(json, h.cube.origin);
    json.key("edge").value(h.cube.edge);
    json.endObject();
    writeLevelsJson(json, h.levels);
    json.key("nodes").value(h.totalNodes);
    json.key("points_stored").value(h.totalPoints);
    json.key("splat_attributes_stored").value(storedSplatPoints(h));
    json.key("verified").value(verified);
    json.endObject();
    std::printf("%s\n", json.text().c_str());
}

void printText(const omh::Header& h, bool verified) {
    std::string attributes;
    for (const std::string& name : attributeNames(h.attributes)) {
        attributes.append(attributes.empty() ? "" : ", ").append(name);
    }
    std::printf("file:        %s\n", h.path.c_str());
    std::printf("format:      OMH hierarchy, version %u, %llu bytes, %zu-byte point records\n",
                h.version, static_cast<unsigned long long>(h.fileBytes), h.recordBytes);
    std::printf("parameters:  depth %d, ratio %.3g, leaf collapse %s\n", h.build.maxLevel,
                h.build.ratio, toString(h.build.collapse));
    std::printf("points:      %llu in, %llu dropped by leaf collapse, %llu leaves collapsed, "
                "%llu stored\n",
                static_cast<unsigned long long>(h.build.inputPoints),
                static_cast<unsigned long long>(h.build.droppedPoints),
                static_cast<unsigned long long>(h.build.collapsedLeaves),
                static_cast<unsigned long long>(h.totalPoints));
    std::printf("attributes:  %s%s\n", attributes.empty() ? "none" : attributes.c_str(),
                h.estimatedNormals ? " (+ estimated normals)" : "");
    std::printf("splats:      stored for %llu points%s\n",
                static_cast<unsigned long long>(storedSplatPoints(h)),
                h.splatsInRecords() ? " (every record)"
                                    : " (of nodes under 8 points; the others are estimated "
                                      "when drawn)");
    std::string uniform;
    for (const std::string& name : uniformColumnNames(h)) {
        uniform.append(uniform.empty() ? "" : ", ").append(name);
    }
    if (!uniform.empty()) {
        std::printf("uniform:     %s (one value for every point, stored once)\n", uniform.c_str());
    }
    std::printf("cube:        origin %.6f %.6f %.6f, edge %.6f; offset %.6f %.6f %.6f\n",
                h.cube.origin.x, h.cube.origin.y, h.cube.origin.z, h.cube.edge,
                h.sourceOffset.x, h.sourceOffset.y, h.sourceOffset.z);
    std::printf("level  nodes        leaves       points\n");
    for (std::size_t level = 0; level < h.levels.size(); ++level) {
        std::printf("%5zu  %-11llu  %-11llu  %llu\n", level,
                    static_cast<unsigned long long>(h.levels[level].nodes),
                    static_cast<unsigned long long>(h.levels[level].leaves),
                    static_cast<unsigned long long>(h.levels[level].points));
    }
    std::printf("checksums:   %s\n", verified ? "every section verified"
                                               : "header, level table and footer verified "
                                                 "(--verify checks every section)");
}

} // namespace

int printOmhInfo(const std::string& path, bool json, bool verify) {
    OmhReader reader(path);
    if (verify) {
        reader.verify();
    }
    if (json) {
        printJson(reader.header(), verify);
    } else {
        printText(reader.header(), verify);
    }
    return 0;
}

} // namespace omicron::cli
