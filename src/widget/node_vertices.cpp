#include "node_vertices.hpp"

#include "build/hierarchy.hpp"
#include "build/splat_encoding.hpp"
#include "points/las_fields.hpp"

#include <algorithm>
#include <cmath>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace omicron {

namespace {

std::uint32_t packSnorm10(float value) {
    const auto quantized =
        static_cast<std::int32_t>(std::lround(std::clamp(value, -1.0f, 1.0f) * 511.0f));
    return static_cast<std::uint32_t>(quantized) & 0x3ffu;
}

// Intensity ranges differ between sensors (0-255 or 0-65535): a logarithmic byte keeps both
// readable without knowing the cloud's maximum before the last point arrived.
std::uint8_t packIntensity(std::uint16_t intensity) {
    return static_cast<std::uint8_t>(std::lround(255.0 * std::log2(1.0 + intensity) / 16.0));
}

} // namespace

std::uint32_t packNormal2101010(float x, float y, float z) {
    return packSnorm10(x) | (packSnorm10(y) << 10) | (packSnorm10(z) << 20);
}

double gpsTimeBaseOf(const Hierarchy& hierarchy, const OctreeNode& node) {
    const SortedCloud& cloud = hierarchy.cloud();
    const AttributeSet attributes = cloud.attributes();
    if (!attributes.has(Attribute::GpsTime) || node.pointCount == 0) {
        return 0.0;
    }
    return decodeLasFields(attributes, cloud.lasRecord(node.heldPoint(0))).gpsTime;
}

void packNodeVertices(const Hierarchy& hierarchy, const OctreeNode& node,
                      std::vector<PointVertex>& out, NodePackScratch& scratch, double gpsTimeBase) {
    const SortedCloud& cloud = hierarchy.cloud();
    hierarchy.nodeSplats(node, scratch.splats, scratch.estimate);
    const NodeSplats& splats = scratch.splats;
    const bool estimatedNormals = !splats.normals.empty();
    const auto inputNormals = cloud.normals();
    const auto intensities = cloud.intensities();
    const bool hasColor = cloud.hasColors();
    const bool hasIntensity = !intensities.empty();
    const AttributeSet attributes = cloud.attributes();
    const bool hasLas = attributes.has(Attribute::Las);
    const bool hasGpsTime = attributes.has(Attribute::GpsTime);

    out.resize(node.pointCount);
    for (std::uint32_t i = 0; i < node.pointCount; ++i) {
        const std::uint32_t point = node.heldPoint(i);
        PointVertex& vertex = out[i];
        const glm::vec3 p = cloud.position(point);
        vertex.x = p.x;
        vertex.y = p.y;
        vertex.z = p.z;
        if (hasColor) {
            const glm::u8vec3 c = cloud.color(point);
            vertex.r = c.r;
            vertex.g = c.g;
            vertex.b = c.b;
        } else {
            vertex.r = vertex.g = vertex.b = 255;
        }
        vertex.intensity = hasIntensity ? packIntensity(intensities[point]) : 0;
        const glm::vec3 normal =
            estimatedNormals ? decodeOctahedral(splats.normals[i]) : inputNormals[point];
        vertex.normal = packNormal2101010(normal.x, normal.y, normal.z);
        vertex.radius = decodeRadius(splats.radii[i]) * node.splatScale;
        if (hasLas) {
            const LasFields las = decodeLasFields(attributes, cloud.lasRecord(point));
            vertex.classification = las.classification;
            vertex.returnNumber = static_cast<std::uint8_t>(las.returnNumber());
            vertex.numberOfReturns = static_cast<std::uint8_t>(las.numberOfReturns());
            vertex.lasFlags = las.flags;
            if (hasGpsTime) {
                vertex.gpsTime = static_cast<float>(las.gpsTime - gpsTimeBase);
                scratch.gpsTimes.add(vertex.gpsTime);
            }
        } else {
            vertex.classification = vertex.returnNumber = vertex.numberOfReturns = 0;
            vertex.lasFlags = 0;
            vertex.gpsTime = 0.0f;
        }
    }
}

ValueRange packNodesVertices(const Hierarchy& hierarchy, std::span<const OctreeNode* const> nodes,
                             std::vector<std::vector<PointVertex>>& out, double gpsTimeBase) {
    if (out.size() < nodes.size()) {
        out.resize(nodes.size());
    }
    tbb::enumerable_thread_specific<NodePackScratch> scratch;
    tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
        packNodeVertices(hierarchy, *nodes[i], out[i], scratch.local(), gpsTimeBase);
    });
    ValueRange range;
    for (const NodePackScratch& local : scratch) {
        range.add(local.gpsTimes);
    }
    return range;
}

} // namespace omicron
