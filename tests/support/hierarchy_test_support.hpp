// Shared by the hierarchy tests: synthetic clouds, builds through the real sorter, the
// brute-force reference octree and a fingerprint of everything a build produced.
#pragma once

#include "build/cut_invariants.hpp"
#include "build/hierarchy_builder.hpp"
#include "io/point_reader.hpp"
#include "sort/morton_sorter.hpp"

#include <algorithm>
#include <cstring>
#include <gtest/gtest.h>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace omicron::test {

enum class Shape {
    Random,
    SinglePoint,
    AllIdentical,
    TwoClusters, // two tight clusters at opposite corners
    MaxFaces,    // points on the x = 1, y = 1 and z = 1 faces and edges
    Duplicates,  // few distinct positions, each repeated many times
    Plane,       // z = 0.3
    Line,        // along the diagonal
};

inline const char* toString(Shape shape) {
    switch (shape) {
    case Shape::Random:
        return "random";
    case Shape::SinglePoint:
        return "single point";
    case Shape::AllIdentical:
        return "all identical";
    case Shape::TwoClusters:
        return "two distant clusters";
    case Shape::MaxFaces:
        return "points on the max faces";
    case Shape::Duplicates:
        return "heavy duplicates";
    case Shape::Plane:
        return "a plane";
    case Shape::Line:
        return "a line";
    }
    return "?";
}

struct SyntheticCloud {
    CloudInfo info;
    PointBatch points; // already in the unit cube, as a reader delivers them
};

inline SyntheticCloud makeCloud(Shape shape, std::size_t count, std::uint64_t seed,
                                bool withNormals = false) {
    if (shape == Shape::SinglePoint) {
        count = 1;
    }
    SyntheticCloud cloud;
    cloud.info.path = std::string("synthetic ") + toString(shape);
    cloud.info.pointCount = count;
    cloud.info.attributes = AttributeSet(Attribute::Color);
    if (withNormals) {
        cloud.info.attributes.add(Attribute::Normal);
    }
    cloud.points.attributes = cloud.info.attributes;
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (std::size_t i = 0; i < count; ++i) {
        glm::vec3 p{unit(random), unit(random), unit(random)};
        switch (shape) {
        case Shape::Random:
            break;
        case Shape::SinglePoint:
            p = glm::vec3(0.3f, 0.6f, 0.9f);
            break;
        case Shape::AllIdentical:
            p = glm::vec3(0.25f, 0.75f, 0.5f);
            break;
        case Shape::TwoClusters:
            p = (i % 2 == 0 ? glm::vec3(0.0f) : glm::vec3(0.999f)) + p * 0.001f;
            break;
        case Shape::MaxFaces:
            if (i % 3 == 0) {
                p.x = 1.0f;
            } else if (i % 3 == 1) {
                p.y = 1.0f;
                p.z = 1.0f;
            } else {
                p = glm::vec3(1.0f);
            }
            break;
        case Shape::Duplicates:
            p = glm::vec3(float(i % 37) / 37.0f, float(i % 5) / 5.0f, 0.5f);
            break;
        case Shape::Plane:
            p.z = 0.3f;
            break;
        case Shape::Line:
            p = glm::vec3(p.x, p.x, p.x);
            break;
        }
        cloud.points.positions.push_back(p);
        cloud.points.colors.push_back(glm::u8vec3(i & 0xff, (i >> 8) & 0xff, 7));
        if (withNormals) {
            cloud.points.normals.push_back(glm::vec3(0.0f, 0.0f, 1.0f));
        }
    }
    return cloud;
}

// Build options with the cut invariants checked after every fix pass.
inline BuildOptions checkedOptions(int maxLevel, LeafCollapse collapse = LeafCollapse::Off) {
    BuildOptions options;
    options.maxLevel = maxLevel;
    options.collapse = collapse;
    options.checkInvariants = true;
    return options;
}

struct BuildResult {
    std::shared_ptr<const SortedCloud> cloud;
    std::unique_ptr<HierarchyBuilder> builder;
};

// Through the real incremental sorter, ranges of `rangePoints` (as in production).
inline BuildResult buildSynthetic(const SyntheticCloud& cloud, const BuildOptions& options,
                                  std::size_t rangePoints = 4096, int sortChunks = 8,
                                  PointStorage storage = PointStorage::Exact) {
    SortOptions sortOptions;
    sortOptions.chunks = sortChunks;
    sortOptions.storage = storage;
    sortOptions.batchPoints = rangePoints;
    IncrementalMortonSorter sorter(cloud.info, sortOptions);
    sorter.add(cloud.points);
    BuildResult result;
    result.cloud = sorter.cloud();
    result.builder = std::make_unique<HierarchyBuilder>(result.cloud, options);
    sorter.sortAndEmit(result.builder->consumer());
    result.builder->finish();
    result.builder->wait();
    return result;
}

// Pipeline 1 exactly as the CLI runs it: open, read + sort, build while ranges arrive.
inline BuildResult buildFile(const std::string& path, const BuildOptions& options,
                             PointStorage storage = PointStorage::Exact) {
    auto reader = openPointCloud(path);
    BuildResult result;
    SortOptions sortOptions;
    sortOptions.storage = storage;
    sortPointCloud(
        *reader, sortOptions,
        [&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
            result.builder->onSortedRange(cloud, begin, end);
        },
        [&](const IncrementalMortonSorter& sorter) {
            result.cloud = sorter.cloud();
            result.builder = std::make_unique<HierarchyBuilder>(result.cloud, options);
        });
    result.builder->finish();
    result.builder->wait();
    return result;
}

// The brute-force octree: every non-empty cell of every level, from the points' codes. With
// leaf collapse, a maxLevel cell that is its parent's only non-empty child is not a node.
inline std::vector<std::vector<morton::Code>> referenceNodes(const SortedCloud& cloud, int maxLevel,
                                                             LeafCollapse collapse) {
    std::vector<std::set<morton::Code>> levels(static_cast<std::size_t>(maxLevel) + 1);
    for (std::size_t i = 0; i < cloud.sortedEnd(); ++i) {
        const morton::Code code = cloud.code(i);
        for (int level = 0; level <= maxLevel; ++level) {
            levels[level].insert(morton::codeAtLevel(code, level));
        }
    }
    if (collapse != LeafCollapse::Off) {
        std::set<morton::Code> kept;
        for (morton::Code leaf : levels[maxLevel]) {
            const auto first = levels[maxLevel].lower_bound((leaf >> 3) << 3);
            const auto last = levels[maxLevel].upper_bound(((leaf >> 3) << 3) | 7);
            if (std::distance(first, last) > 1) {
                kept.insert(leaf);
            }
        }
        levels[maxLevel] = kept;
    }
    std::vector<std::vector<morton::Code>> result;
    for (const auto& level : levels) {
        result.emplace_back(level.begin(), level.end());
    }
    return result;
}

inline std::vector<morton::Code> nodeCodes(const Hierarchy& hierarchy, int level) {
    std::vector<morton::Code> codes;
    for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
        codes.push_back(hierarchy.node(level, i).code);
    }
    return codes;
}

// Checks the finished build: nodes per level against the reference, invariants (during and
// after), statistics, and that the leaves hold the input (all of it unless paper collapse).
inline void expectValidBuild(const BuildResult& result) {
    const HierarchyBuilder& builder = *result.builder;
    const Hierarchy& hierarchy = builder.hierarchy();
    const BuildOptions& options = builder.options();
    const BuildStatistics stats = builder.statistics();
    const SortedCloud& cloud = *result.cloud;
    ASSERT_TRUE(stats.complete);
    ASSERT_TRUE(hierarchy.publishedCut().complete);
    EXPECT_EQ(stats.invariantViolation, "");
    EXPECT_EQ(stats.inputPoints, cloud.capacity());

    CutCheckContext context;
    context.ratio = options.ratio;
    context.collapse = options.collapse;
    context.insertedPoints = stats.inputPoints;
    context.requireCompleteFix = true;
    EXPECT_EQ(checkCutInvariants(builder.cut(), hierarchy, context), "");

    const auto reference = referenceNodes(cloud, options.maxLevel, options.collapse);
    std::uint64_t leafPoints = 0, dropped = 0;
    for (int level = 0; level <= options.maxLevel; ++level) {
        EXPECT_EQ(nodeCodes(hierarchy, level), reference[level]) << "nodes of level " << level;
        std::uint64_t points = 0, leaves = 0;
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            points += node.pointCount;
            if (node.isLeaf()) {
                ++leaves;
                leafPoints += node.pointCount;
                dropped += node.coveredCount - node.pointCount;
            }
        }
        EXPECT_EQ(stats.levels[level].nodes, hierarchy.nodeCount(level)) << level;
        EXPECT_EQ(stats.levels[level].points, points) << level;
        EXPECT_EQ(stats.levels[level].leaves, leaves) << level;
    }
    EXPECT_EQ(stats.droppedPoints, dropped);
    EXPECT_EQ(stats.placeholdersCreated, stats.placeholdersSubstituted);
    EXPECT_EQ(stats.placeholdersCreated, stats.collapsedLeaves);
    if (options.collapse != LeafCollapse::Paper) {
        EXPECT_EQ(dropped, 0u);
        EXPECT_EQ(leafPoints, cloud.capacity()) << "leaves hold exactly the input points";
    } else {
        EXPECT_EQ(leafPoints + dropped, cloud.capacity());
    }
    ASSERT_EQ(builder.cut().roots(0).size(), 1u);
    EXPECT_EQ(hierarchy.nodeCount(0), 1u);
    for (int d = 1; d < 10; ++d) {
        EXPECT_LE(stats.milestonesSeconds[d - 1], stats.milestonesSeconds[d]);
    }
    EXPECT_GE(stats.milestonesSeconds[9], 0.0);
    EXPECT_GE(stats.creationSeconds, stats.milestonesSeconds[9]);
}

// FNV-1a over every byte of the result a renderer could see.
class Fingerprint {
public:
    template <typename T> void add(const T& value) {
        unsigned char bytes[sizeof(T)];
        std::memcpy(bytes, &value, sizeof(T));
        for (unsigned char b : bytes) {
            m_hash = (m_hash ^ b) * 0x100000001b3ull;
        }
    }
    std::uint64_t value() const { return m_hash; }

private:
    std::uint64_t m_hash = 0xcbf29ce484222325ull;
};

// Every node's structure and held points, and (withSplats) the splats a renderer would draw.
inline std::uint64_t fingerprint(const Hierarchy& hierarchy, bool withSplats = true) {
    Fingerprint print;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        print.add(hierarchy.nodeCount(level));
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            print.add(node.code);
            print.add(node.coveredBegin);
            print.add(node.coveredCount);
            print.add(node.pointCount);
            print.add(node.firstChild);
            print.add(node.childCount);
            print.add(node.flags);
            print.add(node.splatScale);
            for (std::uint32_t p = 0; p < node.pointCount; ++p) {
                print.add(node.heldPoint(p));
            }
        }
    }
    if (!withSplats) {
        return print.value();
    }
    // The splat attributes a renderer would draw every node with.
    NodeSplats splats;
    SplatScratch scratch;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            hierarchy.nodeSplats(hierarchy.node(level, i), splats, scratch);
            for (const std::uint16_t radius : splats.radii) {
                print.add(radius);
            }
            for (const std::uint32_t normal : splats.normals) {
                print.add(normal);
            }
        }
    }
    return print.value();
}

} // namespace omicron::test
