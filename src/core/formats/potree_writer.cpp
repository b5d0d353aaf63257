#include "formats/potree_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <string_view>
#include <vector>

namespace omicron {

namespace {

enum PotreeNodeType : std::uint8_t { kNormal = 0, kLeaf = 1, kProxy = 2 };
constexpr std::size_t kRecordBytes = 22;

template <typename T> void store(std::uint8_t* at, const T& value) {
    std::memcpy(at, &value, sizeof(T));
}

// omicron octant (z << 2 | y << 1 | x) -> Potree child index (x << 2 | y << 1 | z).
unsigned potreeChildIndex(morton::Code code) {
    const unsigned octant = static_cast<unsigned>(code & 7u);
    return ((octant & 1u) << 2) | (octant & 2u) | ((octant >> 2) & 1u);
}

std::int32_t quantize(float unit) {
    const double steps = std::floor(static_cast<double>(unit) * kPotreeStepsPerEdge);
    return static_cast<std::int32_t>(std::clamp(steps, 0.0, double(kPotreeStepsPerEdge - 1)));
}

struct NodeRef {
    int level = 0;
    std::uint32_t index = 0;
};

// A node's children in Potree's order: the order a loader expects them in a chunk.
std::vector<NodeRef> potreeChildren(const Hierarchy& hierarchy, NodeRef ref) {
    const OctreeNode& node = hierarchy.node(ref.level, ref.index);
    std::vector<NodeRef> children;
    for (std::uint32_t c = 0; c < node.childCount; ++c) {
        children.push_back({ref.level + 1, node.firstChild + c});
    }
    std::sort(children.begin(), children.end(), [&](NodeRef a, NodeRef b) {
        return potreeChildIndex(hierarchy.node(a.level, a.index).code) <
               potreeChildIndex(hierarchy.node(b.level, b.index).code);
    });
    return children;
}

std::uint8_t potreeChildMask(const Hierarchy& hierarchy, NodeRef ref) {
    std::uint8_t mask = 0;
    for (NodeRef child : potreeChildren(hierarchy, ref)) {
        mask = static_cast<std::uint8_t>(
            mask | (1u << potreeChildIndex(hierarchy.node(child.level, child.index).code)));
    }
    return mask;
}

struct ChunkRecord {
    NodeRef node;
    PotreeNodeType type = kNormal;
    std::size_t proxyChunk = 0; // for proxies: the chunk that starts with this node
};

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

} // namespace

PotreeExportSummary exportPotree(const Hierarchy& hierarchy, const std::string& folder,
                                 const PotreeExportOptions& options) {
    if (!hierarchy.publishedCut().complete || hierarchy.nodeCount(0) != 1) {
        throw OutputError(folder + ": only a complete hierarchy can be exported");
    }
    if (options.stepSize < 1) {
        throw OutputError(folder + ": the hierarchy step size must be at least 1");
    }
    std::error_code error;
    std::filesystem::create_directories(folder, error);
    if (error) {
        throw OutputError(folder + ": cannot create the folder: " + error.message());
    }
    const std::filesystem::path dir(folder);
    const SortedCloud& cloud = hierarchy.cloud();
    const AttributeSet attributes = cloud.attributes();
    const bool rgb = attributes.has(Attribute::Color);
    const bool intensity = attributes.has(Attribute::Intensity);
    const std::size_t pointBytes = 12 + (rgb ? 6 : 0) + (intensity ? 2 : 0);
    const CubeTransform& cube = cloud.cube();
    const std::array<double, 3> boxMin{cube.origin.x + cloud.sourceOffset().x,
                                       cube.origin.y + cloud.sourceOffset().y,
                                       cube.origin.z + cloud.sourceOffset().z};
    const double scale = cube.edge / kPotreeStepsPerEdge;

    PotreeExportSummary summary;
    // octree.bin: every node's points, level by level; remember where each node went.
    std::vector<std::vector<std::uint64_t>> byteOffsets(
        static_cast<std::size_t>(hierarchy.maxLevel()) + 1);
    std::array<double, 3> positionMin{}, positionMax{};
    positionMin.fill(std::numeric_limits<double>::max());
    positionMax.fill(std::numeric_limits<double>::lowest());
    std::array<std::uint16_t, 3> rgbMin{65535, 65535, 65535}, rgbMax{0, 0, 0};
    std::uint16_t intensityMin = 65535, intensityMax = 0;
    int depth = 0;
    {
        AtomicFileWriter octree((dir / "octree.bin").string());
        std::vector<std::uint8_t> record(pointBytes);
        for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
            const std::size_t count = hierarchy.nodeCount(level);
            depth = count > 0 ? level : depth;
            auto& offsets = byteOffsets[static_cast<std::size_t>(level)];
            offsets.resize(count);
            for (std::size_t i = 0; i < count; ++i) {
                const OctreeNode& node = hierarchy.node(level, i);
                offsets[i] = octree.bytesWritten();
                for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                    const std::uint32_t index = node.heldPoint(p);
                    const glm::vec3 unit = cloud.position(index);
                    for (int axis = 0; axis < 3; ++axis) {
                        const std::int32_t stored = quantize(unit[axis]);
                        store(record.data() + 4 * axis, stored);
                        const double value = stored * scale + boxMin[axis];
                        positionMin[axis] = std::min(positionMin[axis], value);
                        positionMax[axis] = std::max(positionMax[axis], value);
                    }
                    std::size_t at = 12;
                    if (rgb) {
                        const glm::u8vec3 color = cloud.color(index);
                        for (int c = 0; c < 3; ++c) {
                            const auto value = static_cast<std::uint16_t>(color[c] * 257u);
                            store(record.data() + at + 2 * c, value);
                            rgbMin[c] = std::min(rgbMin[c], value);
                            rgbMax[c] = std::max(rgbMax[c], value);
                        }
                        at += 6;
                    }
                    if (intensity) {
                        const std::uint16_t value = cloud.intensities()[index];
                        store(record.data() + at, value);
                        intensityMin = std::min(intensityMin, value);
                        intensityMax = std::max(intensityMax, value);
                    }
                    octree.write(record.data(), record.size());
                }
                ++summary.nodes;
                summary.points += node.pointCount;
            }
        }
        summary.octreeBytes = octree.bytesWritten();
        octree.commit();
    }

    // hierarchy.bin: chunks laid out first (their sizes give the proxies' offsets), then
    // written in order; the root's chunk comes first.
    std::vector<std::vector<ChunkRecord>> chunks;
    std::deque<NodeRef> chunkRoots{{0, 0}};
    while (!chunkRoots.empty()) {
        const NodeRef root = chunkRoots.front();
        chunkRoots.pop_front();
        std::vector<ChunkRecord> records;
        std::deque<NodeRef> queue{root};
        while (!queue.empty()) {
            const NodeRef ref = queue.front();
            queue.pop_front();
            const OctreeNode& node = hierarchy.node(ref.level, ref.index);
            ChunkRecord record{ref, node.childCount == 0 ? kLeaf : kNormal, 0};
            if (node.childCount > 0 && ref.level - root.level == options.stepSize) {
                record.type = kProxy;
                record.proxyChunk = chunks.size() + 1 + chunkRoots.size();
                chunkRoots.push_back(ref);
            } else {
                for (NodeRef child : potreeChildren(hierarchy, ref)) {
                    queue.push_back(child);
                }
            }
            records.push_back(record);
        }
        chunks.push_back(std::move(records));
    }
    std::vector<std::uint64_t> chunkOffsets(chunks.size() + 1, 0);
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        chunkOffsets[c + 1] = chunkOffsets[c] + chunks[c].size() * kRecordBytes;
    }
    {
        AtomicFileWriter file((dir / "hierarchy.bin").string());
        std::array<std::uint8_t, kRecordBytes> bytes{};
        for (const auto& chunk : chunks) {
            for (const ChunkRecord& record : chunk) {
                const OctreeNode& node = hierarchy.node(record.node.level, record.node.index);
                const bool proxy = record.type == kProxy;
                store(bytes.data() + 0, static_cast<std::uint8_t>(record.type));
                store(bytes.data() + 1, potreeChildMask(hierarchy, record.node));
                store(bytes.data() + 2, node.pointCount);
                store(bytes.data() + 6,
                      proxy ? chunkOffsets[record.proxyChunk]
                            : byteOffsets[static_cast<std::size_t>(record.node.level)]
                                         [record.node.index]);
                store(bytes.data() + 14,
                      proxy ? chunkOffsets[record.proxyChunk + 1] - chunkOffsets[record.proxyChunk]
                            : std::uint64_t{node.pointCount} * pointBytes);
                file.write(bytes.data(), bytes.size());
            }
        }
        file.commit();
    }
    summary.chunks = chunks.size();

    // Appended piece by piece: GCC 12's -Wrestrict misfires on "literal" + std::string.
    std::string json;
    const auto add = [&json](std::initializer_list<std::string_view> pieces) {
        for (std::string_view piece : pieces) {
            json.append(piece);
        }
    };
    const double edge = cube.edge;
    add({"{\n  \"version\": \"2.0\",\n  \"name\": \"", jsonEscape(options.name), "\",\n"});
    add({"  \"description\": \"exported by omicron\",\n"});
    add({"  \"points\": ", std::to_string(summary.points), ",\n  \"projection\": \"\",\n"});
    add({"  \"hierarchy\": {\n    \"firstChunkSize\": ", std::to_string(chunkOffsets[1]),
         ",\n    \"stepSize\": ", std::to_string(options.stepSize), ",\n    \"depth\": ",
         std::to_string(depth), "\n  },\n"});
    add({"  \"offset\": ", triple(boxMin), ",\n  \"scale\": ", triple({scale, scale, scale}),
         ",\n  \"spacing\": ", number(edge / 128.0), ",\n"});
    add({"  \"boundingBox\": {\n    \"min\": ", triple(boxMin), ",\n    \"max\": ",
         triple({boxMin[0] + edge, boxMin[1] + edge, boxMin[2] + edge}), "\n  },\n"});
    add({"  \"encoding\": \"DEFAULT\",\n  \"attributes\": [\n"});
    add({"    {\"name\": \"position\", \"description\": \"\", \"size\": 12, "
         "\"numElements\": 3, \"elementSize\": 4, \"type\": \"int32\", \"min\": ",
         triple(positionMin), ", \"max\": ", triple(positionMax), "}"});
    if (rgb) {
        add({",\n    {\"name\": \"rgb\", \"description\": \"\", \"size\": 6, "
             "\"numElements\": 3, \"elementSize\": 2, \"type\": \"uint16\", \"min\": ",
             triple({double(rgbMin[0]), double(rgbMin[1]), double(rgbMin[2])}), ", \"max\": ",
             triple({double(rgbMax[0]), double(rgbMax[1]), double(rgbMax[2])}), "}"});
    }
    if (intensity) {
        add({",\n    {\"name\": \"intensity\", \"description\": \"\", \"size\": 2, "
             "\"numElements\": 1, \"elementSize\": 2, \"type\": \"uint16\", \"min\": [",
             number(intensityMin), "], \"max\": [", number(intensityMax), "]}"});
    }
    add({"\n  ]\n}\n"});
    AtomicFileWriter metadata((dir / "metadata.json").string());
    metadata.write(json);
    metadata.commit();
    return summary;
}

} // namespace omicron
