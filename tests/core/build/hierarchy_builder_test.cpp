// The parallel builder end to end: real sorter ranges in, the brute-force reference octree,
// the invariants after every fix pass, identical results for any threads / worklist size /
// range size, leaf collapse, cancellation, and a reader thread traversing while it builds.
#include "hierarchy_test_support.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <thread>
#include <tuple>

namespace omicron {
namespace {

using test::buildSynthetic;
using test::checkedOptions;
using test::expectValidBuild;
using test::fingerprint;
using test::makeCloud;
using test::Shape;

TEST(HierarchyBuilder, RejectsOptionsOutOfRange) {
    const auto cloud =
        std::make_shared<SortedCloud>(CubeTransform{}, glm::dvec3(0.0), AttributeSet{}, 0);
    const auto expectRejected = [&](BuildOptions options, const char* what) {
        EXPECT_THROW(HierarchyBuilder(cloud, options), std::invalid_argument) << what;
    };
    BuildOptions options;
    options.maxLevel = 0;
    expectRejected(options, "depth 0");
    options.maxLevel = 22;
    expectRejected(options, "depth 22");
    options = {};
    options.ratio = 0.0;
    expectRejected(options, "ratio 0");
    options.ratio = 1.5;
    expectRejected(options, "ratio 1.5");
    options = {};
    options.worklistSize = 0;
    expectRejected(options, "worklist 0");
    try {
        options = {};
        options.maxLevel = 30;
        HierarchyBuilder builder(cloud, options);
        FAIL() << "depth 30 accepted";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("got 30"), std::string::npos) << error.what();
    }
}

TEST(HierarchyBuilder, EmptyCloudCompletesWithNoNodes) {
    const auto cloud =
        std::make_shared<SortedCloud>(CubeTransform{}, glm::dvec3(0.0), AttributeSet{}, 0);
    cloud->markComplete();
    HierarchyBuilder builder(cloud, checkedOptions(5));
    builder.finish();
    builder.wait();
    const BuildStatistics stats = builder.statistics();
    EXPECT_TRUE(stats.complete);
    EXPECT_EQ(stats.invariantViolation, "");
    EXPECT_EQ(stats.totalNodes(), 0u);
    EXPECT_TRUE(builder.hierarchy().publishedCut().complete);
}

struct ShapeCase {
    Shape shape;
    std::size_t points;
};

TEST(HierarchyBuilder, AdversarialCloudsMatchTheReferenceOctree) {
    const ShapeCase cases[] = {
        {Shape::Random, 20000},     {Shape::SinglePoint, 1}, {Shape::AllIdentical, 5000},
        {Shape::TwoClusters, 8000}, {Shape::MaxFaces, 6000}, {Shape::Duplicates, 9000},
        {Shape::Plane, 12000},      {Shape::Line, 7000},
    };
    for (const ShapeCase& c : cases) {
        for (const int maxLevel : {1, 2, 5, 9, 21}) {
            for (const LeafCollapse collapse :
                 {LeafCollapse::Off, LeafCollapse::Lossless, LeafCollapse::Paper}) {
                SCOPED_TRACE(std::string(test::toString(c.shape)) + ", depth " +
                             std::to_string(maxLevel) + ", collapse " + toString(collapse));
                const auto cloud = makeCloud(c.shape, c.points, 42);
                const auto result = buildSynthetic(cloud, checkedOptions(maxLevel, collapse), 1000);
                expectValidBuild(result);
                if (HasFatalFailure()) {
                    return;
                }
            }
        }
    }
}

TEST(HierarchyBuilder, LeafCollapseModesKeepOrDropTheLonelyLeavesPoints) {
    // Two distant clusters at depth 9: long chains, so many maxLevel leaves have no sibling.
    const auto cloud = makeCloud(Shape::TwoClusters, 3000, 5);
    const auto off = buildSynthetic(cloud, checkedOptions(9, LeafCollapse::Off));
    const auto lossless = buildSynthetic(cloud, checkedOptions(9, LeafCollapse::Lossless));
    const auto paper = buildSynthetic(cloud, checkedOptions(9, LeafCollapse::Paper));
    const BuildStatistics offStats = off.builder->statistics();
    const BuildStatistics losslessStats = lossless.builder->statistics();
    const BuildStatistics paperStats = paper.builder->statistics();
    EXPECT_EQ(offStats.collapsedLeaves, 0u);
    EXPECT_GT(losslessStats.collapsedLeaves, 0u);
    EXPECT_EQ(losslessStats.collapsedLeaves, paperStats.collapsedLeaves);
    EXPECT_EQ(losslessStats.droppedPoints, 0u);
    EXPECT_GT(paperStats.droppedPoints, 0u) << "paper collapse must count what it drops";
    EXPECT_LT(losslessStats.totalNodes(), offStats.totalNodes());
    EXPECT_EQ(losslessStats.levels[9].nodes + losslessStats.collapsedLeaves,
              offStats.levels[9].nodes);
    expectValidBuild(lossless);
    expectValidBuild(paper);
}

TEST(HierarchyBuilder, ParentsHoldTheRatioOfTheirChildrensPoints) {
    const auto cloud = makeCloud(Shape::Random, 40000, 3);
    for (const double ratio : {0.2, 0.25, 1.0}) {
        BuildOptions options = checkedOptions(4);
        options.ratio = ratio;
        const auto result = buildSynthetic(cloud, options);
        expectValidBuild(result); // checks every sample: size, ascending, from the children
        const Hierarchy& hierarchy = result.builder->hierarchy();
        const OctreeNode& parent = hierarchy.node(3, 0);
        std::uint64_t childPoints = 0;
        for (std::uint32_t c = 0; c < parent.childCount; ++c) {
            childPoints += hierarchy.node(4, parent.firstChild + c).pointCount;
        }
        EXPECT_EQ(parent.pointCount,
                  static_cast<std::uint32_t>(std::llround(ratio * double(childPoints))));
    }
}

// Every sample is the stratified pick of its children's held points, in one list (a
// paper-collapsed leaf: of its covered range), whether stored or implicit; a sample is stored
// only when some child does not hold its whole range.
TEST(HierarchyBuilder, ParentsHoldTheStratifiedPicksOfTheirChildrensPoints) {
    const auto cloud = makeCloud(Shape::Random, 30000, 11);
    for (const LeafCollapse collapse :
         {LeafCollapse::Off, LeafCollapse::Lossless, LeafCollapse::Paper}) {
        const auto result = buildSynthetic(cloud, checkedOptions(6, collapse));
        const Hierarchy& hierarchy = result.builder->hierarchy();
        const auto expectPicks = [](const OctreeNode& node,
                                    const std::vector<std::uint32_t>& list) {
            const std::uint64_t n = list.size(), count = node.pointCount;
            ASSERT_LE(count, n);
            for (std::uint32_t j = 0; j < count; ++j) {
                ASSERT_EQ(node.heldPoint(j), list[(2 * j + 1) * n / (2 * count)])
                    << "node " << std::hex << node.code << std::dec << " pick " << j;
            }
        };
        std::size_t implicitParents = 0, storedParents = 0;
        for (int level = 0; level < hierarchy.maxLevel(); ++level) {
            for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
                const OctreeNode& node = hierarchy.node(level, i);
                std::vector<std::uint32_t> list;
                bool childrenHoldRanges = true;
                if (node.isLeaf()) {
                    for (std::uint32_t k = 0; k < node.coveredCount; ++k) {
                        list.push_back(node.coveredBegin + k);
                    }
                } else {
                    for (std::uint32_t c = 0; c < node.childCount; ++c) {
                        const OctreeNode& child = hierarchy.node(level + 1, node.firstChild + c);
                        childrenHoldRanges = childrenHoldRanges && child.holdsRange();
                        for (std::uint32_t k = 0; k < child.pointCount; ++k) {
                            list.push_back(child.heldPoint(k));
                        }
                    }
                    (childrenHoldRanges ? implicitParents : storedParents) += 1;
                }
                EXPECT_EQ(node.sampleIndices == nullptr, childrenHoldRanges)
                    << "level " << level << " node " << i;
                expectPicks(node, list);
            }
        }
        EXPECT_GT(implicitParents, 0u) << toString(collapse);
        EXPECT_GT(storedParents, 0u) << toString(collapse);
    }
}

TEST(HierarchyBuilder, ResultIsIdenticalForEveryThreadCountWorklistAndRangeSize) {
    // Random points plus a dense cluster: many sibling groups straddle worklist boundaries.
    auto cloud = makeCloud(Shape::Random, 30000, 11);
    const auto cluster = makeCloud(Shape::TwoClusters, 20000, 12);
    cloud.points.positions.insert(cloud.points.positions.end(), cluster.points.positions.begin(),
                                  cluster.points.positions.end());
    cloud.points.colors.insert(cloud.points.colors.end(), cluster.points.colors.begin(),
                               cluster.points.colors.end());
    cloud.info.pointCount = cloud.points.size();
    for (const LeafCollapse collapse :
         {LeafCollapse::Off, LeafCollapse::Lossless, LeafCollapse::Paper}) {
        BuildOptions options = checkedOptions(8, collapse);
        const auto reference = buildSynthetic(cloud, options, 65536, 1);
        expectValidBuild(reference);
        const std::uint64_t expected = fingerprint(reference.builder->hierarchy());
        for (const int threads : {1, 2, 4}) {
            tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                            static_cast<std::size_t>(threads));
            for (const std::size_t worklist : {1, 3, 8, 16, 32, 64, 128}) {
                SCOPED_TRACE(std::string("collapse ") + toString(collapse) + ", " +
                             std::to_string(threads) + " threads, worklist " +
                             std::to_string(worklist));
                options.threads = threads;
                options.worklistSize = worklist;
                const std::size_t rangePoints = worklist == 3 ? 97 : 4096;
                const auto result = buildSynthetic(cloud, options, rangePoints, 16);
                EXPECT_EQ(result.builder->statistics().invariantViolation, "");
                EXPECT_EQ(fingerprint(result.builder->hierarchy()), expected);
                if (worklist < 8) {
                    EXPECT_GT(result.builder->statistics().duplicateParentsMerged, 0u)
                        << "small worklists must split sibling groups";
                }
            }
        }
    }
}

TEST(HierarchyBuilder, CancelBeforeAnyInputLeavesAnEmptyValidCut) {
    const auto cloud = makeCloud(Shape::Random, 1000, 1);
    IncrementalMortonSorter sorter(cloud.info, {});
    HierarchyBuilder builder(sorter.cloud(), checkedOptions(6));
    builder.cancel();
    builder.wait();
    const BuildStatistics stats = builder.statistics();
    EXPECT_TRUE(stats.cancelled);
    EXPECT_FALSE(stats.complete);
    EXPECT_EQ(checkCutInvariants(builder.cut(), builder.hierarchy(), {}), "");
}

TEST(HierarchyBuilder, DestroyingARunningBuilderStopsIt) {
    const auto cloud = makeCloud(Shape::Random, 50000, 2);
    SortOptions sortOptions;
    sortOptions.batchPoints = 1000;
    IncrementalMortonSorter sorter(cloud.info, sortOptions);
    sorter.add(cloud.points);
    auto builder = std::make_unique<HierarchyBuilder>(sorter.cloud(), checkedOptions(7));
    int ranges = 0;
    sorter.sortAndEmit([&](const SortedCloud& sorted, std::size_t begin, std::size_t end) {
        if (++ranges <= 10) {
            builder->onSortedRange(sorted, begin, end);
        }
    });
    builder.reset(); // no finish(), no wait(): must not hang
    SUCCEED();
}

TEST(HierarchyBuilder, CancelMidBuildLeavesAValidCut) {
    const auto cloud = makeCloud(Shape::Random, 120000, 8);
    for (const LeafCollapse collapse : {LeafCollapse::Off, LeafCollapse::Paper}) {
        for (int attempt = 0; attempt < 8; ++attempt) {
            SCOPED_TRACE(std::string("collapse ") + toString(collapse) + ", attempt " +
                         std::to_string(attempt));
            SortOptions sortOptions;
            sortOptions.batchPoints = 2000;
            IncrementalMortonSorter sorter(cloud.info, sortOptions);
            sorter.add(cloud.points);
            BuildOptions options = checkedOptions(8, collapse);
            options.worklistSize = 8;
            HierarchyBuilder builder(sorter.cloud(), options);
            // Cancel from a third thread at a different moment each attempt.
            std::thread canceller([&] {
                std::this_thread::sleep_for(std::chrono::microseconds(300 * attempt * attempt));
                builder.cancel();
            });
            sorter.sortAndEmit(builder.consumer());
            builder.finish();
            builder.wait();
            canceller.join();
            const BuildStatistics stats = builder.statistics();
            EXPECT_EQ(stats.invariantViolation, "");
            CutCheckContext context;
            context.ratio = options.ratio;
            context.collapse = collapse;
            context.insertedPoints = stats.inputPoints;
            EXPECT_EQ(checkCutInvariants(builder.cut(), builder.hierarchy(), context), "");
            EXPECT_EQ(stats.complete, !stats.cancelled);
            EXPECT_LE(stats.inputPoints, cloud.points.size());
        }
    }
}

// A render-side reader: loads the published cut, then walks every published node that is
// settled (not a root of the cut nor a child of one), its children and its points. Every
// node it may see must be complete and must never change. Run under TSan to prove the
// protocol race-free; here it checks the content. With parallelism 1, oneTBB runs every task
// on the thread that spawns it, so TSan sees only the three threads of the protocol (sorter,
// builder, reader) and no hand-off inside an uninstrumented libtbb (Debian's is not built
// for TSan); with full parallelism it needs an instrumented oneTBB.
class HierarchyBuilderConcurrency : public testing::TestWithParam<int> {};

TEST_P(HierarchyBuilderConcurrency, ReaderTraversesSettledNodesWhileBuilding) {
    std::unique_ptr<tbb::global_control> parallelism;
    if (GetParam() > 0) {
        parallelism = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(GetParam()));
    }
    const auto cloud = makeCloud(Shape::Random, 300000, 21);
    SortOptions sortOptions;
    sortOptions.batchPoints = 1500;
    sortOptions.chunks = 32;
    IncrementalMortonSorter sorter(cloud.info, sortOptions);
    sorter.add(cloud.points);
    BuildOptions options = checkedOptions(8, LeafCollapse::Lossless);
    options.checkInvariants = false; // keep the builder fast: more states to observe
    options.worklistSize = 16;
    test::BuildResult result{sorter.cloud(),
                             std::make_unique<HierarchyBuilder>(sorter.cloud(), options)};
    HierarchyBuilder& builder = *result.builder;
    const Hierarchy& hierarchy = builder.hierarchy();
    const int maxLevel = options.maxLevel;

    std::atomic<bool> stop{false};
    std::string error;
    std::uint64_t traversals = 0, partialTraversalsWithNodes = 0, nodesVisited = 0;
    std::thread reader([&] {
        morton::Code lastDelimiter = 0;
        NodeSplats splats;
        SplatScratch splatScratch;
        const auto check = [&](bool ok, const std::string& what) {
            if (!ok && error.empty()) {
                error = what;
            }
            return ok;
        };
        // One more traversal after the build ended, to walk the complete hierarchy too.
        for (bool last = false; !last && error.empty();) {
            last = stop.load(std::memory_order_acquire);
            const PublishedCut cut = hierarchy.publishedCut();
            check(cut.delimiter >= lastDelimiter, "m_C went backwards");
            lastDelimiter = cut.delimiter;
            const std::size_t sortedEnd = hierarchy.cloud().sortedEnd();
            std::uint64_t settled = 0;
            for (int level = 1; level <= maxLevel && error.empty(); ++level) {
                const std::size_t count = hierarchy.nodeCount(level);
                for (std::size_t i = 0; i < count && error.empty(); ++i) {
                    const OctreeNode& node = hierarchy.node(level, i);
                    if (!Hierarchy::isSettled(node.code, cut, maxLevel)) {
                        continue;
                    }
                    ++settled;
                    // Its parent exists and lists it among its children.
                    const auto parent =
                        hierarchy.findNode(node.code >> 3, hierarchy.nodeCount(level - 1));
                    if (!check(parent.has_value(), "a settled node has no parent")) {
                        break;
                    }
                    const OctreeNode& p = hierarchy.node(level - 1, *parent);
                    check(p.firstChild <= i && i < p.firstChild + p.childCount,
                          "a settled node is not among its parent's children");
                    const std::size_t children =
                        level < maxLevel ? hierarchy.nodeCount(level + 1) : 0;
                    check(node.firstChild + std::size_t{node.childCount} <= children ||
                              node.childCount == 0,
                          "children beyond the published nodes");
                    for (std::uint32_t c = 0; c < node.childCount; ++c) {
                        const OctreeNode& child = hierarchy.node(level + 1, node.firstChild + c);
                        check((child.code >> 3) == node.code, "a child is not below its parent");
                    }
                    bool heldPublished = true;
                    for (std::uint32_t k = 0; k < node.pointCount && heldPublished; ++k) {
                        const std::uint32_t point = node.heldPoint(k);
                        heldPublished =
                            check(point < sortedEnd, "a held point beyond the sorted prefix") &&
                            check(hierarchy.cloud().positions()[point].x >= 0.0f,
                                  "a held point outside the unit cube");
                    }
                    // What a renderer does with a settled node while the build goes on.
                    if (heldPublished) {
                        hierarchy.nodeSplats(node, splats, splatScratch);
                        check(splats.radii.size() == node.pointCount &&
                                  std::all_of(splats.radii.begin(), splats.radii.end(),
                                              [](std::uint16_t r) { return r > 0; }),
                              "a settled node without splat radii");
                    }
                    ++nodesVisited;
                }
            }
            ++traversals;
            if (!cut.complete && settled > 0) {
                ++partialTraversalsWithNodes;
            }
        }
    });
    // Ranges arrive at a pace the builder keeps up with, so it publishes many cuts.
    sorter.sortAndEmit([&](const SortedCloud& sorted, std::size_t begin, std::size_t end) {
        builder.onSortedRange(sorted, begin, end);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
    builder.finish();
    builder.wait();
    stop.store(true, std::memory_order_release);
    reader.join();
    EXPECT_EQ(error, "");
    EXPECT_GT(traversals, 0u);
    EXPECT_GT(nodesVisited, 0u);
    EXPECT_GT(partialTraversalsWithNodes, 0u) << "the reader never saw a settled node mid-build";
    RecordProperty("traversals", std::to_string(traversals));
    RecordProperty("traversalsDuringBuild", std::to_string(partialTraversalsWithNodes));
    expectValidBuild(result);
}

INSTANTIATE_TEST_SUITE_P(Parallelism, HierarchyBuilderConcurrency, testing::Values(1, 0),
                         [](const testing::TestParamInfo<int>& info) {
                             return info.param == 1 ? std::string("OneThreadPerRole")
                                                    : std::string("AllCores");
                         });

} // namespace
} // namespace omicron

namespace omicron {
namespace {

// The positions the leaves hold, against the file read again: the same multiset.
void expectLeavesHoldTheFilesPoints(const test::BuildResult& result, const std::string& path) {
    const LoadedCloud loaded = loadPointCloud(path);
    const Hierarchy& hierarchy = result.builder->hierarchy();
    std::vector<glm::vec3> held;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            const OctreeNode& node = hierarchy.node(level, i);
            for (std::uint32_t p = 0; node.isLeaf() && p < node.pointCount; ++p) {
                held.push_back(hierarchy.cloud().positions()[node.heldPoint(p)]);
            }
        }
    }
    std::vector<glm::vec3> input(loaded.points.positions.begin(), loaded.points.positions.end());
    const auto less = [](const glm::vec3& a, const glm::vec3& b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    };
    std::sort(held.begin(), held.end(), less);
    std::sort(input.begin(), input.end(), less);
    ASSERT_EQ(held.size(), input.size());
    EXPECT_TRUE(held == input) << "the leaves do not hold exactly the input points";
}

class HierarchyBuilderSharedData : public testing::TestWithParam<const char*> {};

TEST_P(HierarchyBuilderSharedData, MatchesTheReferenceOctreeAndHoldsEveryPoint) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    const auto result = test::buildFile(path, checkedOptions(8));
    expectValidBuild(result);
    expectLeavesHoldTheFilesPoints(result, path);
}

INSTANTIATE_TEST_SUITE_P(EveryFile, HierarchyBuilderSharedData,
                         testing::Values("bunny.ply", "dragon.ply", "lion.ply", "sorvilier.ply",
                                         "indoor.ply", "autzen_trim.ply", "autzen_trim.las"),
                         test::FileParamName());

TEST(HierarchyBuilderSharedData, LeafCollapseOnARealScan) {
    OMICRON_REQUIRE_SHARED_FILE(path, "lion.ply");
    for (const LeafCollapse collapse : {LeafCollapse::Lossless, LeafCollapse::Paper}) {
        SCOPED_TRACE(toString(collapse));
        const auto result = test::buildFile(path, checkedOptions(9, collapse));
        expectValidBuild(result);
        EXPECT_GT(result.builder->statistics().collapsedLeaves, 0u);
        if (collapse == LeafCollapse::Lossless) {
            expectLeavesHoldTheFilesPoints(result, path);
        }
    }
}

TEST(HierarchyBuilderSharedData, AutzenSouthAtDepthSeven) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_south.ply");
    const auto result = test::buildFile(path, checkedOptions(7));
    expectValidBuild(result);
    expectLeavesHoldTheFilesPoints(result, path);
    const BuildStatistics stats = result.builder->statistics();
    RecordProperty("creation_s", std::to_string(stats.creationSeconds));
    RecordProperty("after_input_s", std::to_string(stats.creationSeconds - stats.inputEndSeconds));
}

} // namespace
} // namespace omicron
