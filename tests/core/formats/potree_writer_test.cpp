// The Potree 2.0 export, read back as Potree's loader reads it: metadata.json's fields, the
// hierarchy chunks (proxies followed into their chunks), each node's box by Potree's child
// subdivision, every point decoded from octree.bin and checked against its node's box.
#include "formats/potree_writer.hpp"
#include "hierarchy_test_support.hpp"
#include "test_files.hpp"

#include <cstring>
#include <deque>
#include <gtest/gtest.h>
#include <regex>

namespace omicron::test {
namespace {

template <typename T> T loadLe(const std::uint8_t* at) {
    T value;
    std::memcpy(&value, at, sizeof(T));
    return value;
}

std::string text(const std::string& path) {
    const auto bytes = readBytes(path);
    return std::string(bytes.begin(), bytes.end());
}

double numberField(const std::string& json, const std::string& pattern) {
    std::smatch match;
    EXPECT_TRUE(std::regex_search(json, match, std::regex(pattern))) << pattern;
    return match.empty() ? 0.0 : std::stod(match[1]);
}

std::array<double, 3> tripleField(const std::string& json, const std::string& prefix) {
    const std::string number = R"(\s*([-+0-9.eE]+)\s*)";
    std::smatch match;
    EXPECT_TRUE(std::regex_search(json, match,
                                  std::regex(prefix + R"(\s*\[)" + number + "," + number + "," +
                                             number + R"(\])")))
        << prefix;
    if (match.empty()) {
        return {};
    }
    return {std::stod(match[1]), std::stod(match[2]), std::stod(match[3])};
}

struct Box {
    std::array<double, 3> min, max;
};

// Potree's createChildAABB: bit 0 halves z, bit 1 y, bit 2 x.
Box childBox(const Box& box, unsigned index) {
    Box child = box;
    for (int axis = 0; axis < 3; ++axis) {
        const unsigned bit = 1u << (2 - axis);
        const double half = (box.max[axis] - box.min[axis]) / 2;
        if ((index & bit) != 0) {
            child.min[axis] += half;
        } else {
            child.max[axis] -= half;
        }
    }
    return child;
}

struct PotreeNode {
    Box box;
    int level = 0;
};

void expectValidExport(const Hierarchy& hierarchy, const std::string& folder, int stepSize) {
    const std::string metadata = text(folder + "/metadata.json");
    const auto hierarchyBytes = readBytes(folder + "/hierarchy.bin");
    const auto octree = readBytes(folder + "/octree.bin");
    EXPECT_NE(metadata.find(R"("version": "2.0")"), std::string::npos);
    EXPECT_NE(metadata.find(R"("encoding": "DEFAULT")"), std::string::npos);
    const bool rgb = hierarchy.cloud().attributes().has(Attribute::Color);
    const bool intensity = hierarchy.cloud().attributes().has(Attribute::Intensity);
    EXPECT_EQ(metadata.find(R"("name": "rgb")") != std::string::npos, rgb);
    EXPECT_EQ(metadata.find(R"("name": "intensity")") != std::string::npos, intensity);
    EXPECT_NE(metadata.find(R"("name": "position", "description": "", "size": 12, )"
                            R"("numElements": 3, "elementSize": 4, "type": "int32")"),
              std::string::npos);
    const std::size_t pointBytes = 12 + (rgb ? 6 : 0) + (intensity ? 2 : 0);
    const auto points = static_cast<std::uint64_t>(numberField(metadata, R"("points": (\d+))"));
    const auto firstChunk =
        static_cast<std::size_t>(numberField(metadata, R"("firstChunkSize": (\d+))"));
    EXPECT_EQ(numberField(metadata, R"("stepSize": (\d+))"), stepSize);
    const auto offset = tripleField(metadata, R"("offset":)");
    const auto scale = tripleField(metadata, R"("scale":)");
    Box root{tripleField(metadata, R"("min":)"), tripleField(metadata, R"("max":)")};
    const CubeTransform& cube = hierarchy.cloud().cube();
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_DOUBLE_EQ(root.min[axis], cube.origin[axis] + hierarchy.cloud().sourceOffset()[axis]);
        EXPECT_DOUBLE_EQ(root.max[axis] - root.min[axis], cube.edge);
    }

    // Potree's parseHierarchy, chunk by chunk: records in breadth-first order, children by
    // child index; a proxy's chunk starts with the proxy node itself.
    std::vector<std::uint64_t> nodesPerLevel(hierarchy.maxLevel() + 1, 0);
    std::uint64_t pointSum = 0, proxies = 0;
    struct Pending {
        PotreeNode node;
        std::size_t chunkOffset, chunkBytes;
    };
    std::deque<Pending> chunks{{{root, 0}, 0, firstChunk}};
    const double edge = cube.edge;
    while (!chunks.empty()) {
        const Pending chunk = chunks.front();
        chunks.pop_front();
        ASSERT_EQ(chunk.chunkBytes % 22, 0u);
        ASSERT_LE(chunk.chunkOffset + chunk.chunkBytes, hierarchyBytes.size());
        std::vector<PotreeNode> nodes{chunk.node};
        for (std::size_t i = 0; i < chunk.chunkBytes / 22; ++i) {
            ASSERT_LT(i, nodes.size()) << "a chunk holds more records than its nodes announce";
            const std::uint8_t* record = hierarchyBytes.data() + chunk.chunkOffset + 22 * i;
            const auto type = record[0];
            const auto childMask = record[1];
            const auto numPoints = loadLe<std::uint32_t>(record + 2);
            const auto byteOffset = loadLe<std::uint64_t>(record + 6);
            const auto byteSize = loadLe<std::uint64_t>(record + 14);
            const PotreeNode node = nodes[i];
            ASSERT_LE(type, 2);
            if (type == 2) {
                ASSERT_NE(i, 0u) << "a chunk starts with its real node, not a proxy";
                EXPECT_EQ(node.level - chunk.node.level, stepSize);
                chunks.push_back({node, byteOffset, byteSize});
                ++proxies;
                continue;
            }
            EXPECT_EQ(type == 1, childMask == 0);
            ++nodesPerLevel[node.level];
            pointSum += numPoints;
            ASSERT_GT(numPoints, 0u);
            ASSERT_EQ(byteSize, std::uint64_t{numPoints} * pointBytes);
            ASSERT_LE(byteOffset + byteSize, octree.size());
            // Every point inside its node's box (the floor quantisation guarantees it).
            const double slack = edge * 1e-12;
            for (std::uint32_t p = 0; p < numPoints; ++p) {
                const std::uint8_t* at = octree.data() + byteOffset + p * pointBytes;
                for (int axis = 0; axis < 3; ++axis) {
                    const double value = loadLe<std::int32_t>(at + 4 * axis) * scale[axis] + offset[axis];
                    ASSERT_GE(value, node.box.min[axis] - slack) << "level " << node.level;
                    ASSERT_LE(value, node.box.max[axis] + slack) << "level " << node.level;
                }
            }
            for (unsigned child = 0; child < 8; ++child) {
                if ((childMask & (1u << child)) != 0) {
                    nodes.push_back({childBox(node.box, child), node.level + 1});
                }
            }
        }
        ASSERT_EQ(nodes.size(), chunk.chunkBytes / 22) << "records and announced nodes differ";
    }
    EXPECT_EQ(pointSum, points);
    std::uint64_t heldPoints = 0;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        EXPECT_EQ(nodesPerLevel[level], hierarchy.nodeCount(level)) << "level " << level;
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            heldPoints += hierarchy.node(level, i).pointCount;
        }
    }
    EXPECT_EQ(points, heldPoints);
    EXPECT_EQ(octree.size(), heldPoints * pointBytes);
    if (hierarchy.maxLevel() > stepSize && hierarchy.nodeCount(stepSize + 1) > 0) {
        EXPECT_GT(proxies, 0u) << "deep hierarchies are split into chunks";
    }
}

TEST(PotreeExport, BuiltSyntheticCloudParsesBackAgainstTheFormat) {
    TempDir dir;
    BuildOptions options;
    options.maxLevel = 6;
    const BuildResult built = buildSynthetic(makeCloud(Shape::Random, 20000, 9), options);
    for (int stepSize : {1, 2, 4}) {
        SCOPED_TRACE(stepSize);
        PotreeExportOptions exportOptions;
        exportOptions.stepSize = stepSize;
        const std::string folder = dir.file("potree" + std::to_string(stepSize));
        exportPotree(built.builder->hierarchy(), folder, exportOptions);
        expectValidExport(built.builder->hierarchy(), folder, stepSize);
    }
}

TEST(PotreeExport, GeoreferencedScanWithColourAndIntensity) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.las");
    TempDir dir;
    BuildOptions options;
    options.maxLevel = 7;
    options.collapse = LeafCollapse::Paper;
    const BuildResult built = buildFile(path, options);
    exportPotree(built.builder->hierarchy(), dir.file("autzen"));
    expectValidExport(built.builder->hierarchy(), dir.file("autzen"), 4);
}

TEST(PotreeExport, IncompleteHierarchyIsRefused) {
    TempDir dir;
    const auto cloud = std::make_shared<SortedCloud>(CubeTransform{}, glm::dvec3(0.0),
                                                     AttributeSet{}, 10);
    Hierarchy hierarchy(cloud, 3);
    EXPECT_THROW(exportPotree(hierarchy, dir.file("p")), OutputError);
}

} // namespace
} // namespace omicron::test
