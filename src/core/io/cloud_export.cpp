#include "io/cloud_export.hpp"

#include "io/atomic_file_writer.hpp"
#include "io/las/las_extra_bytes.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_writer.hpp"
#include "io/ply/ply_writer.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace omicron {

namespace {

std::string lowerExtension(const std::string& path) {
    const auto dot = path.find_last_of('.');
    const auto slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
        return {};
    }
    std::string extension = path.substr(dot);
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

} // namespace

namespace {

// Keeps the points of `points` inside `box` (unit cube), attributes alongside, in place: the
// export holds the cloud's copy once, not a second filtered one.
void keepInsideBox(PointBatch& points, const ClipBox& box) {
    const AttributeSet attributes = points.attributes;
    const std::size_t lasBytes = attributes.lasBytes();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!box.contains(glm::dvec3(points.positions[i]))) {
            continue;
        }
        points.positions[kept] = points.positions[i];
        if (attributes.has(Attribute::Normal)) {
            points.normals[kept] = points.normals[i];
        }
        if (attributes.has(Attribute::Color)) {
            points.colors[kept] = points.colors[i];
        }
        if (attributes.has(Attribute::Intensity)) {
            points.intensities[kept] = points.intensities[i];
        }
        std::copy_n(points.las.begin() + static_cast<std::ptrdiff_t>(i * lasBytes), lasBytes,
                    points.las.begin() + static_cast<std::ptrdiff_t>(kept * lasBytes));
        ++kept;
    }
    points.positions.resize(kept);
    if (attributes.has(Attribute::Normal)) {
        points.normals.resize(kept);
    }
    if (attributes.has(Attribute::Color)) {
        points.colors.resize(kept);
    }
    if (attributes.has(Attribute::Intensity)) {
        points.intensities.resize(kept);
    }
    points.las.resize(kept * lasBytes);
}

} // namespace

std::uint64_t exportCloudPoints(const std::string& path, const SortedCloud& cloud,
                                const std::optional<ClipBox>& clip) {
    const std::string extension = lowerExtension(path);
    if (extension != ".ply" && extension != ".las") {
        throw OutputError(path + ": cannot export points: expected a .ply or .las file name");
    }
    if (cloud.sortedEnd() == 0) {
        throw OutputError(path + ": cannot export points: the cloud holds no sorted points");
    }
    PointBatch points;
    cloud.copyRange(0, cloud.sortedEnd(), points);
    if (clip) {
        keepInsideBox(points, toUnitCube(*clip, cloud.cube()));
        if (points.empty()) {
            throw OutputError(path + ": cannot export points: none lies inside the clip box");
        }
    }
    if (extension == ".ply") {
        PlyWriteOptions options;
        options.offset = plyStorageOffset(cloud.cube(), cloud.sourceOffset());
        options.comments.push_back("exported by omicron (points in Morton order)");
        writePly(path, points, cloud.cube(), options);
        return points.size();
    }
    const LasWriteOptions options =
        lasExportOptions(cloud.attributes(), cloud.cube(), cloud.lasExtraBytesDescriptors(),
                         cloud.lasProjectionRecords());
    writeLas(path, points, cloud.cube(), options);
    return points.size();
}

LasWriteOptions lasExportOptions(AttributeSet attributes, const CubeTransform& cube,
                                 const std::vector<std::uint8_t>& extraBytesDescriptors,
                                 const std::vector<std::uint8_t>& projectionRecords) {
    LasWriteOptions options;
    options.vlrs = parseVariableLengthRecords(projectionRecords);
    const bool color = attributes.has(Attribute::Color);
    if (attributes.has(Attribute::Las)) {
        // Every LAS field back: LAS 1.4's formats keep full classes, scan angles and NIR.
        options.versionMinor = 4;
        options.pointFormat = attributes.has(Attribute::Nir) ? 8 : color ? 7 : 6;
        options.extraBytesPerRecord = attributes.extraBytes();
        if (las::describesExtraBytes(extraBytesDescriptors, attributes.extraBytes())) {
            options.vlrs.push_back({"LASF_Spec", las::kExtraBytesRecordId, "Extra Bytes Record",
                                    extraBytesDescriptors});
        } else if (attributes.extraBytes() != 0) {
            options.vlrs.push_back(undocumentedExtraBytesRecord(attributes.extraBytes()));
        }
    } else {
        options.pointFormat = color ? 2 : 0;
    }
    // Integers relative to the cube's corner, with the finest power-of-ten step that keeps the
    // largest coordinate (the cube's edge) below 10^9 < 2^31: sub-millimetre for a building,
    // still exact enough for a 10 cm statue.
    options.offset = cube.origin;
    const double step = std::pow(10.0, std::ceil(std::log10(cube.edge / 1e9)));
    options.scale = glm::dvec3(step);
    return options;
}

} // namespace omicron
