// omicron-cli info FILE [--json]: reads a whole cloud, streaming, and reports what it holds and
// how fast it was read.
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/omh_reader.hpp"
#include "formats/oms_reader.hpp"
#include "io/las/las_extra_bytes.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_writer.hpp"
#include "io/point_reader.hpp"
#include "json_writer.hpp"
#include "omh_info.hpp"
#include "points/attribute_statistics.hpp"

#include <chrono>
#include <cstdio>

namespace omicron::cli {

namespace {

// The coordinate system a LAS file declares: its WKT (record 2112), else "GeoTIFF keys"
// (record 34735), else "".
std::string coordinateSystem(const CloudInfo& info) {
    std::string found;
    for (const LasVariableLengthRecord& record :
         parseVariableLengthRecords(info.lasProjectionRecords)) {
        if (record.recordId == 2112) {
            return las::fixedLengthText(record.payload.data(), record.payload.size());
        }
        if (record.recordId == 34735) {
            found = "GeoTIFF keys";
        }
    }
    return found;
}

struct InfoReport {
    std::string formatName; // "PLY binary little-endian", "OMS sorted stream", ...
    CloudInfo info;
    ReadSummary summary;
    AttributeStatistics statistics;
    double openSeconds = 0.0; // header and bounds pre-pass
    double readSeconds = 0.0; // open and the full read
};

void writeVector(JsonWriter& json, const glm::dvec3& v) {
    json.beginArray().value(v.x).value(v.y).value(v.z).endArray();
}

void printJson(const InfoReport& report) {
    const CloudInfo& info = report.info;
    JsonWriter json;
    json.beginObject();
    json.key("path").value(info.path);
    json.key("format").value(report.formatName);
    json.key("format_detail").value(info.formatDetail);
    json.key("points_declared").value(info.pointCount);
    json.key("points_read").value(report.summary.pointsDelivered);
    json.key("skipped_non_finite").value(report.summary.skippedNonFinite);
    json.key("attributes").beginArray();
    for (const std::string& name : attributeNames(info.attributes)) {
        json.value(name);
    }
    json.endArray();
    json.key("extra_bytes").beginArray();
    for (const las::ExtraBytesField& field :
         las::parseExtraBytesDescriptors(info.lasExtraBytesDescriptors)) {
        json.beginObject();
        json.key("name").value(field.name);
        json.key("type").value(las::extraBytesTypeName(field));
        json.key("description").value(field.description);
        json.endObject();
    }
    json.endArray();
    json.key("attribute_ranges").beginObject();
    for (const NamedRange& range : report.statistics.ranges()) {
        json.key(range.name).beginArray().value(range.range.min).value(range.range.max).endArray();
    }
    json.endObject();
    if (info.attributes.has(Attribute::Las)) {
        json.key("classes").beginObject();
        const auto& counts = report.statistics.classCounts();
        for (int c = 0; c < kLasClassCount; ++c) {
            if (counts[static_cast<std::size_t>(c)] != 0) {
                json.key(std::to_string(c)).value(counts[static_cast<std::size_t>(c)]);
            }
        }
        json.endObject();
    }
    json.key("bounds").beginObject();
    json.key("min");
    writeVector(json, info.sourceBounds.min);
    json.key("max");
    writeVector(json, info.sourceBounds.max);
    json.endObject();
    json.key("bounds_from_header").value(info.boundsFromHeader);
    json.key("coordinate_system").value(coordinateSystem(info));
    json.key("offset");
    writeVector(json, info.sourceOffset);
    json.key("cube").beginObject();
    json.key("origin");
    writeVector(json, info.cube.origin);
    json.key("edge").value(info.cube.edge);
    json.endObject();
    json.key("read_s").value(report.readSeconds);
    json.endObject();
    std::printf("%s\n", json.text().c_str());
}

void printText(const InfoReport& report) {
    const CloudInfo& info = report.info;
    const auto& b = info.sourceBounds;
    std::string attributes;
    for (const std::string& name : attributeNames(info.attributes)) {
        attributes += (attributes.empty() ? "" : ", ") + name;
    }
    std::printf("file:        %s\n", info.path.c_str());
    std::printf("format:      %s (%s)\n", report.formatName.c_str(), info.formatDetail.c_str());
    std::printf("points:      %llu declared, %llu read, %llu non-finite skipped\n",
                static_cast<unsigned long long>(info.pointCount),
                static_cast<unsigned long long>(report.summary.pointsDelivered),
                static_cast<unsigned long long>(report.summary.skippedNonFinite));
    std::printf("attributes:  %s\n",
                attributes.empty() ? "none (positions only)" : attributes.c_str());
    for (const las::ExtraBytesField& field :
         las::parseExtraBytesDescriptors(info.lasExtraBytesDescriptors)) {
        std::printf("  extra bytes: %s (%s)%s%s\n", field.name.c_str(),
                    las::extraBytesTypeName(field).c_str(), field.description.empty() ? "" : ": ",
                    field.description.c_str());
    }
    for (const NamedRange& range : report.statistics.ranges()) {
        std::printf("  %-22s %.12g .. %.12g\n", range.name.c_str(), range.range.min,
                    range.range.max);
    }
    const auto& counts = report.statistics.classCounts();
    for (int c = 0; info.attributes.has(Attribute::Las) && c < kLasClassCount; ++c) {
        if (counts[static_cast<std::size_t>(c)] != 0) {
            std::printf("  class %3d %-24s %llu points\n", c, lasClassName(c).c_str(),
                        static_cast<unsigned long long>(counts[static_cast<std::size_t>(c)]));
        }
    }
    std::printf("bounds min:  %.6f %.6f %.6f\n", b.min.x, b.min.y, b.min.z);
    std::printf("bounds max:  %.6f %.6f %.6f  (source units, %s)\n", b.max.x, b.max.y, b.max.z,
                info.boundsFromHeader ? "from the header" : "from the points");
    const std::string crs = coordinateSystem(info);
    if (!crs.empty()) {
        // A WKT runs to kilobytes: its start names the system.
        std::printf("coordinates: %s%s\n", crs.substr(0, 100).c_str(),
                    crs.size() > 100 ? "..." : "");
    }
    std::printf("offset:      %.6f %.6f %.6f\n", info.sourceOffset.x, info.sourceOffset.y,
                info.sourceOffset.z);
    std::printf("cube:        origin %.6f %.6f %.6f, edge %.6f\n", info.cube.origin.x,
                info.cube.origin.y, info.cube.origin.z, info.cube.edge);
    const double seconds = report.readSeconds;
    const double rate = seconds > 0.0 ? report.summary.pointsDelivered / seconds : 0.0;
    std::printf("read:        %.3f s (%.3f s opening), %.2f million points/s\n", seconds,
                report.openSeconds, rate / 1e6);
}

using Clock = std::chrono::steady_clock;

double secondsBetween(Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
}

InfoReport readCloud(const std::string& path) {
    const auto start = Clock::now();
    const auto reader = openPointCloud(path);
    const auto opened = Clock::now();
    InfoReport report;
    report.formatName = toString(reader->info().format);
    report.info = reader->info();
    report.summary = reader->read([&](const PointBatch& batch) { report.statistics.add(batch); });
    report.openSeconds = secondsBetween(start, opened);
    report.readSeconds = secondsBetween(start, Clock::now());
    return report;
}

// A .oms sorted stream: the header gives the cube; the bounds come from the points, which
// are read in full so that every checksum and the Morton order are verified too.
InfoReport readSortedStream(const std::string& path) {
    const auto start = Clock::now();
    OmsReader reader(path);
    const auto opened = Clock::now();
    const OmsInfo& oms = reader.info();
    InfoReport report;
    report.formatName = "OMS sorted stream";
    report.info.path = path;
    report.info.formatDetail = "omicron .oms version " + std::to_string(oms.version) +
                               ", Morton order at depth " + std::to_string(oms.sortDepth) + ", " +
                               std::to_string(oms.recordBytes) + "-byte records";
    // Columns stored once in the header (version 2) instead of in every record.
    if (oms.uniform.intensityUniform()) {
        report.info.formatDetail += ", uniform intensity " + std::to_string(oms.uniform.intensity);
    }
    if (oms.uniform.lasUniform()) {
        report.info.formatDetail += ", uniform LAS record";
    }
    report.info.pointCount = oms.pointCount;
    report.info.attributes = oms.attributes;
    report.info.sourceOffset = oms.sourceOffset;
    report.info.cube = oms.cube;
    Bounds bounds;
    PointBatch batch;
    report.summary = reader.read([&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            bounds.extend(cloud.cube().toSource(cloud.position(i)));
        }
        cloud.copyRange(begin, end, batch);
        report.statistics.add(batch);
    });
    report.info.sourceBounds = bounds;
    report.openSeconds = secondsBetween(start, opened);
    report.readSeconds = secondsBetween(start, Clock::now());
    return report;
}

int runInfo(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, {{"json", false}, {"verify", false}});
    if (parsed.help) {
        printCommandHelp(infoCommand());
        return 0;
    }
    if (parsed.positionals.size() != 1) {
        throw UsageError("expected one FILE, found " + std::to_string(parsed.positionals.size()) +
                         " arguments");
    }
    const std::string& path = parsed.positionals[0];
    if (isOmhFile(path)) {
        return printOmhInfo(path, parsed.flag("json"), parsed.flag("verify"));
    }
    if (parsed.flag("verify")) {
        throw UsageError("--verify applies to .omh hierarchy files; other files are always "
                         "read (and .oms checksums verified) in full");
    }
    const InfoReport report = isOmsFile(path) ? readSortedStream(path) : readCloud(path);
    if (parsed.flag("json")) {
        printJson(report);
    } else {
        printText(report);
    }
    return 0;
}

} // namespace

const Command& infoCommand() {
    static const Command command{
        "info", "read a point cloud and describe it (format, count, bounds, speed)",
        "info FILE [--json] [--verify]",
        "Reads the whole file (PLY, LAS, LAZ, XYZ text or a .oms sorted stream, whose\n"
        "checksums and Morton order are verified), streaming, and prints its format, the\n"
        "declared and read point counts, the attributes, the bounding box in source units,\n"
        "the source offset, the unit-cube transform, skipped non-finite points and the read\n"
        "speed. Each attribute's range follows the list (colour per channel; LAS fields:\n"
        "classification, returns, scan angle in degrees, user data, point source id, scanner\n"
        "channel, flags, GPS time, NIR), then the points of each class present.\n"
        "\n"
        "  --json   print one JSON object instead (keys: path, format, format_detail,\n"
        "           points_declared, points_read, skipped_non_finite, attributes,\n"
        "           attribute_ranges {name: [min, max]}, classes {class: points}, bounds,\n"
        "           bounds_from_header, offset, cube, read_s)\n"
        "\n"
        "For a .omh hierarchy file it prints the build parameters, the attributes, the cube\n"
        "and the nodes, leaves and points per level from the header and level table (whose\n"
        "checksums, and the footer's, are checked); --json gives \"levels\":[{\"level\",\n"
        "\"nodes\",\"leaves\",\"points\"}] as build --json does.\n"
        "\n"
        "  --verify (.omh) also read every node table and point section and compare its\n"
        "           checksum; exit status 1 on the first mismatch\n"
        "\n"
        "Exit status: 0 ok, 1 the file cannot be read (the message names the file and where),\n"
        "2 a usage error.\n",
        runInfo};
    return command;
}

} // namespace omicron::cli
