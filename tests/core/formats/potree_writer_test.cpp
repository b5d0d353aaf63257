// The Potree 2.0 export, read back as Potree's loader reads it: metadata.json's fields, the
// hierarchy chunks (proxies followed into their chunks), each node's box by Potree's child
// subdivision, every point decoded from octree.bin and checked against its node's box, and the
// counts of an additive octree (each input point once). potree_roundtrip_test.cpp compares the
// decoded points with the input; the CLI tests load the folder in a real Potree client.
#include "formats/potree_writer.hpp"
#include "hierarchy_test_support.hpp"
#include "std_regex.hpp"
#include "test_files.hpp"

#include <atomic>
#include <cstring>
#include <deque>
#include <filesystem>
#include <gtest/gtest.h>

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
    EXPECT_TRUE(std::regex_search(
        json, match,
        std::regex(prefix + R"(\s*\[)" + number + "," + number + "," + number + R"(\])")))
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

void expectValidExport(const Hierarchy& hierarchy, const std::string& folder, int stepSize,
                       std::uint64_t droppedPoints = 0) {
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
    // PotreeConverter's order for LAS input: position, intensity, ..., rgb.
    if (rgb && intensity) {
        EXPECT_LT(metadata.find(R"("name": "intensity")"), metadata.find(R"("name": "rgb")"));
    }
    // The LAS fields: return number, number of returns, classification, scan angle (2), user
    // data, point source id (2), and the GPS time (8) where the source has it.
    const AttributeSet attributes = hierarchy.cloud().attributes();
    const bool las = attributes.has(Attribute::Las);
    EXPECT_EQ(metadata.find(R"("name": "classification")") != std::string::npos, las);
    EXPECT_EQ(metadata.find(R"("name": "gps-time")") != std::string::npos,
              attributes.has(Attribute::GpsTime));
    const std::size_t pointBytes = 12 + (rgb ? 6 : 0) + (intensity ? 2 : 0) + (las ? 8 : 0) +
                                   (attributes.has(Attribute::GpsTime) ? 8 : 0);
    const auto points = static_cast<std::uint64_t>(numberField(metadata, R"("points": (\d+))"));
    const auto firstChunk =
        static_cast<std::size_t>(numberField(metadata, R"("firstChunkSize": (\d+))"));
    EXPECT_EQ(numberField(metadata, R"("stepSize": (\d+))"), stepSize);
    const auto offset = tripleField(metadata, R"("offset":)");
    const auto scale = tripleField(metadata, R"("scale":)");
    Box root{tripleField(metadata, R"("min":)"), tripleField(metadata, R"("max":)")};
    const CubeTransform& cube = hierarchy.cloud().cube();
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_DOUBLE_EQ(root.min[axis],
                         cube.origin[axis] + hierarchy.cloud().sourceOffset()[axis]);
        EXPECT_DOUBLE_EQ(root.max[axis] - root.min[axis], cube.edge);
        // PotreeConverter: offset = the box minimum, spacing = edge / 128.
        EXPECT_DOUBLE_EQ(offset[axis], root.min[axis]);
    }
    EXPECT_DOUBLE_EQ(numberField(metadata, R"("spacing": ([-+0-9.eE]+))"), cube.edge / 128.0);

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
            // A subtree that stores no point is left out: every leaf written has points.
            if (type == 1) {
                ASSERT_GT(numPoints, 0u) << "level " << node.level;
            }
            ASSERT_EQ(byteSize, std::uint64_t{numPoints} * pointBytes);
            ASSERT_LE(byteOffset + byteSize, octree.size());
            // Every point inside its node's box (the floor quantisation guarantees it).
            const double slack = edge * 1e-12;
            for (std::uint32_t p = 0; p < numPoints; ++p) {
                const std::uint8_t* at = octree.data() + byteOffset + p * pointBytes;
                for (int axis = 0; axis < 3; ++axis) {
                    const double value =
                        loadLe<std::int32_t>(at + 4 * axis) * scale[axis] + offset[axis];
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
    // Additive: every input point once, less those the paper's leaf collapse dropped.
    EXPECT_EQ(points, hierarchy.cloud().sortedEnd() - droppedPoints);
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        EXPECT_LE(nodesPerLevel[level], hierarchy.nodeCount(level)) << "level " << level;
    }
    EXPECT_EQ(nodesPerLevel[0], 1u);
    EXPECT_EQ(octree.size(), points * pointBytes);
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
    const PotreeExportSummary summary =
        exportPotree(built.builder->hierarchy(), dir.file("autzen"));
    const std::uint64_t dropped = built.builder->statistics().droppedPoints;
    EXPECT_GT(dropped, 0u) << "the paper's collapse drops points of this scan at depth 7";
    EXPECT_EQ(summary.droppedPoints, dropped);
    EXPECT_EQ(summary.points + dropped, 110000u);
    expectValidExport(built.builder->hierarchy(), dir.file("autzen"), 4, dropped);
}

// Leftovers of an export beside `folder`: its temporary folders (".NAME.tmp-XXXXXX").
std::vector<std::string> temporaries(const std::filesystem::path& folder) {
    std::vector<std::string> found;
    for (const auto& entry : std::filesystem::directory_iterator(folder.parent_path())) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("." + folder.filename().string() + ".tmp-", 0) == 0) {
            found.push_back(name);
        }
    }
    return found;
}

TEST(PotreeExport, CancelLeavesNothingBehind) {
    TempDir dir;
    BuildOptions options;
    options.maxLevel = 5;
    const BuildResult built = buildSynthetic(makeCloud(Shape::Random, 20000, 4), options);
    std::atomic<bool> cancel{false};
    PotreeExportOptions exportOptions;
    exportOptions.cancel = &cancel;
    std::uint64_t calls = 0, lastDone = 0, lastTotal = 0;
    exportOptions.onProgress = [&](std::uint64_t done, std::uint64_t total) {
        EXPECT_GE(done, lastDone);
        lastDone = done;
        lastTotal = total;
        if (++calls == 10) {
            cancel = true; // half-way: octree.bin is being written
        }
    };
    const std::string folder = dir.file("potree");
    EXPECT_THROW(exportPotree(built.builder->hierarchy(), folder, exportOptions),
                 PotreeExportCancelled);
    EXPECT_FALSE(std::filesystem::exists(folder));
    EXPECT_TRUE(temporaries(folder).empty());
    EXPECT_LT(lastDone, lastTotal);

    // Uncancelled, progress ends at its total.
    cancel = false;
    calls = 0;
    lastDone = 0;
    exportOptions.cancel = nullptr;
    exportPotree(built.builder->hierarchy(), folder, exportOptions);
    EXPECT_EQ(lastDone, lastTotal);
    EXPECT_TRUE(temporaries(folder).empty());
}

TEST(PotreeExport, ReplacesAnOldExportButNoOtherFolder) {
    TempDir dir;
    BuildOptions options;
    options.maxLevel = 4;
    const BuildResult small = buildSynthetic(makeCloud(Shape::Random, 3000, 1), options);
    const BuildResult large = buildSynthetic(makeCloud(Shape::Random, 9000, 2), options);
    const std::string folder = dir.file("potree");
    exportPotree(small.builder->hierarchy(), folder);
    exportPotree(large.builder->hierarchy(), folder); // an old export is replaced whole
    EXPECT_NE(text(folder + "/metadata.json").find("\"points\": 9000"), std::string::npos);
    EXPECT_TRUE(temporaries(folder).empty());

    const std::string mine = dir.file("mine");
    std::filesystem::create_directories(mine);
    writeText(mine + "/notes.txt", "keep me");
    try {
        exportPotree(small.builder->hierarchy(), mine);
        ADD_FAILURE() << "a folder with other files was replaced";
    } catch (const OutputError& error) {
        EXPECT_NE(std::string(error.what()).find("notes.txt"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find(mine), std::string::npos) << error.what();
    }
    EXPECT_EQ(text(mine + "/notes.txt"), "keep me");
    EXPECT_TRUE(temporaries(mine).empty());

    writeText(dir.file("file"), "x");
    EXPECT_THROW(exportPotree(small.builder->hierarchy(), dir.file("file")), OutputError);
    EXPECT_THROW(exportPotree(small.builder->hierarchy(), dir.file("missing/sub")), OutputError);
}

TEST(PotreeExport, IncompleteHierarchyIsRefused) {
    TempDir dir;
    const auto cloud =
        std::make_shared<SortedCloud>(CubeTransform{}, glm::dvec3(0.0), AttributeSet{}, 10);
    Hierarchy hierarchy(cloud, 3);
    EXPECT_THROW(exportPotree(hierarchy, dir.file("p")), OutputError);
}

} // namespace
} // namespace omicron::test
