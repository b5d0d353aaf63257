// A .omh opened with its points paged in on demand (formats/omh_pager.hpp): the front asks for
// nodes, the loader thread reads them while the front keeps drawing an ancestor, the least
// recently used are evicted under the budget and their pages given back. Every evaluation is
// checked against the front's invariants, which include "no entry whose points are missing",
// and every drawn node's points against a whole-file load of the same file.
#include "formats/omh_pager.hpp"
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "front/front.hpp"
#include "front/front_settle.hpp"
#include "hierarchy_test_support.hpp"
#include "pipeline/build_pipeline.hpp"
#include "test_files.hpp"

#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

namespace omicron::test {
namespace {

std::string saveBuilt(const TempDir& dir, const SyntheticCloud& cloud, int depth,
                      std::uint32_t formatVersion = omh::kVersion) {
    const BuildResult built = buildSynthetic(cloud, checkedOptions(depth, LeafCollapse::Off));
    const std::string path = dir.file("paged.omh");
    OmhWriteOptions options;
    options.formatVersion = formatVersion;
    writeOmh(path, built.builder->hierarchy(),
             omhBuildInfo(built.builder->options(), built.builder->statistics()), options);
    return path;
}

std::shared_ptr<const Hierarchy> loadWhole(const std::string& path) {
    OmhReader reader(path);
    auto hierarchy = reader.hierarchy();
    reader.load();
    return hierarchy;
}

// Opens `reader`'s file with its points paged in on demand under `budget`: nodes only.
std::shared_ptr<const Hierarchy> openPaged(OmhReader& reader, std::uint64_t budget) {
    reader.pageOnDemand(budget);
    auto hierarchy = reader.hierarchy();
    reader.load();
    return hierarchy;
}

FrontOptions fullDetail() {
    FrontOptions options;
    options.projectionThresholdPx = 0.0;
    options.pointBudget = 0;
    options.cpuBudgetMs = 0.0;
    return options;
}

// Orthographic, looking at the box of half-size `half` around `centre` (the rest of the cube
// is outside the frustum), at `pixelsPerUnit`.
FrontCamera lookingAt(glm::dvec3 centre, double half, double pixelsPerUnit) {
    FrontCamera camera;
    camera.orthographic = true;
    camera.pixelsPerUnitAtUnitDistance = pixelsPerUnit;
    camera.viewProjection = glm::dmat4(1.0);
    camera.viewProjection[0][0] = camera.viewProjection[1][1] = 1.0 / half;
    camera.viewProjection[2][2] = 2.0; // all depths
    camera.viewProjection[3] =
        glm::dvec4(-centre.x / half, -centre.y / half, -1.0, 1.0);
    return camera;
}

// The held points of every front entry equal those of the same node in the whole-file load.
void expectFrontPointsEqual(const Front& front, const Hierarchy& paged, const Hierarchy& whole) {
    const SortedCloud& a = paged.cloud();
    const SortedCloud& b = whole.cloud();
    NodeSplats pagedSplats, wholeSplats;
    SplatScratch scratch;
    for (const FrontEntry& entry : front.entries()) {
        ASSERT_FALSE(entry.placeholder);
        const int level = entry.level();
        ASSERT_TRUE(paged.pointsResident(level, entry.index));
        const OctreeNode& node = paged.node(level, entry.index);
        ASSERT_EQ(node.coveredBegin, whole.node(level, entry.index).coveredBegin);
        for (std::uint32_t p = 0; p < node.pointCount; ++p) {
            const std::size_t i = node.coveredBegin + p;
            ASSERT_EQ(std::memcmp(&a.positions()[i], &b.positions()[i], sizeof(glm::vec3)), 0)
                << "level " << level << " node " << entry.index << " point " << p;
            if (a.attributes().has(Attribute::Color)) {
                ASSERT_EQ(a.colors()[i], b.colors()[i]);
            }
            const std::size_t lasBytes = a.attributes().lasBytes();
            if (lasBytes != 0) { // no LAS column: no record to compare (and memcmp of null)
                ASSERT_EQ(std::memcmp(a.lasRecord(i), b.lasRecord(i), lasBytes), 0)
                    << "the LAS fields of level " << level << " node " << entry.index << " point "
                    << p;
            }
        }
        paged.nodeSplats(node, pagedSplats, scratch);
        whole.nodeSplats(whole.node(level, entry.index), wholeSplats, scratch);
        ASSERT_EQ(pagedSplats.radii, wholeSplats.radii);
        ASSERT_EQ(pagedSplats.normals, wholeSplats.normals);
    }
}

// Evaluates until nothing changes and no load is pending (settleFront), checking the invariants
// after every call; returns the calls made.
int settlePaged(Front& front, const FrontCamera& camera, const FrontOptions& options) {
    const SettleResult result =
        settleFront(front, camera, options, SettleLimits{INT_MAX, 60.0},
                    [&] { EXPECT_EQ(front.checkInvariants(), ""); });
    if (!result.settled) {
        ADD_FAILURE() << "the paged front did not settle in 60 s";
        return 0;
    }
    return result.evaluations;
}

std::size_t leafCount(const Hierarchy& hierarchy) {
    std::size_t leaves = 0;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
            leaves += hierarchy.node(level, i).childCount == 0 ? 1 : 0;
        }
    }
    return leaves;
}

// Pages of `bytes` at `data` that are in memory now.
std::size_t residentPages(const void* data, std::size_t bytes) {
    const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    std::vector<unsigned char> in((bytes + page - 1) / page);
    EXPECT_EQ(mincore(const_cast<void*>(data), bytes, in.data()), 0);
    std::size_t count = 0;
    for (unsigned char c : in) {
        count += c & 1;
    }
    return count;
}

TEST(OmhPagedLoad, NodesOnlyAtOpenThenEveryLeafOnDemandEqualToTheWholeLoad) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Random, 60000, 11), 6);
    const auto whole = loadWhole(path);

    OmhReader reader(path);
    const auto paged = openPaged(reader, std::uint64_t{1} << 30); // everything fits: nothing is evicted
    ASSERT_NE(paged->residency(), nullptr);
    EXPECT_TRUE(paged->cloud().pagedOnDemand());
    EXPECT_EQ(paged->residency()->stats().loads, 0u) << "opening reads nodes, not points";
    EXPECT_EQ(paged->cloud().sortedEnd(), 0u);
    for (int level = 0; level <= paged->maxLevel(); ++level) {
        ASSERT_EQ(paged->nodeCount(level), whole->nodeCount(level));
    }

    Front front(paged);
    const FrontEvaluation first = front.evaluate(lookingAt({0.5, 0.5, 0.5}, 0.5, 1e9), fullDetail());
    EXPECT_EQ(first.frontSize, 0u) << "the root is drawn only once its points are in memory";
    settlePaged(front, lookingAt({0.5, 0.5, 0.5}, 0.5, 1e9), fullDetail());
    EXPECT_EQ(front.entries().size(), leafCount(*paged));
    expectFrontPointsEqual(front, *paged, *whole);
    // Among them nodes too sparse for an estimate, whose stored attributes the pager reads.
    EXPECT_GT(std::count_if(front.entries().begin(), front.entries().end(),
                            [&](const FrontEntry& entry) {
                                return paged->node(entry.level(), entry.index).pointCount <
                                       kMinPointsPerSplatEstimate;
                            }),
              0);
    const ResidencyStats stats = paged->residency()->stats();
    EXPECT_EQ(stats.evictions, 0u);
    EXPECT_EQ(stats.failedNodes, 0u);
    EXPECT_EQ(stats.pendingLoads, 0u);
    std::uint64_t frontPoints = 0;
    for (const FrontEntry& entry : front.entries()) {
        frontPoints += paged->node(entry.level(), entry.index).pointCount;
    }
    EXPECT_EQ(stats.heldBytes, frontPoints * OmhPager::residentBytesPerPoint(reader.header()));
    EXPECT_GT(stats.loads, leafCount(*paged)) << "the front passed through the inner levels";
}

TEST(OmhPagedLoad, ALasScanPagesItsLasFieldsWithItsPoints) {
    OMICRON_REQUIRE_SHARED_FILE(las, "laz/terrascan_fmt8.laz");
    TempDir dir;
    const BuildResult built = buildFile(las, checkedOptions(5, LeafCollapse::Off));
    const std::string path = dir.file("paged.omh");
    writeOmh(path, built.builder->hierarchy(),
             omhBuildInfo(built.builder->options(), built.builder->statistics()));
    const auto whole = loadWhole(path);
    ASSERT_EQ(whole->cloud().attributes().extraBytes(), 3);
    OmhReader reader(path);
    const auto paged = openPaged(reader, std::uint64_t{1} << 30);
    Front front(paged);
    settlePaged(front, lookingAt({0.5, 0.5, 0.5}, 0.5, 1e9), fullDetail());
    EXPECT_EQ(front.entries().size(), leafCount(*paged));
    expectFrontPointsEqual(front, *paged, *whole);
}

TEST(OmhPagedLoad, ATinyBudgetEvictsAndReloadsAndNeverDrawsAMissingNode) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Random, 120000, 12), 6);
    const auto whole = loadWhole(path);

    OmhReader reader(path);
    const std::uint64_t all = reader.residentBytesOfAllPoints();
    const std::uint64_t budget = all / 24; // more than one corner needs, less than two
    const auto paged = openPaged(reader, budget);
    Front front(paged);

    // Full detail of one corner, then another, then the first again: the second evicts the
    // first's leaves, the third loads them again.
    const FrontCamera cornerA = lookingAt({0.1, 0.1, 0.5}, 0.08, 1e9);
    const FrontCamera cornerB = lookingAt({0.9, 0.9, 0.5}, 0.08, 1e9);
    std::uint64_t loadsBefore = 0;
    for (const FrontCamera* camera : {&cornerA, &cornerB, &cornerA}) {
        settlePaged(front, *camera, fullDetail());
        expectFrontPointsEqual(front, *paged, *whole);
        // One more frame so that eviction has seen the settled front.
        front.evaluate(*camera, fullDetail());
        const ResidencyStats stats = paged->residency()->stats();
        EXPECT_LE(stats.residentBytes, std::max(budget, stats.heldBytes))
            << "beyond the budget, only what the front holds stays";
        EXPECT_GT(stats.loads, loadsBefore);
        loadsBefore = stats.loads;
    }
    const ResidencyStats stats = paged->residency()->stats();
    EXPECT_GT(stats.evictions, 0u);
    EXPECT_EQ(stats.failedNodes, 0u);
    // The evicted pages went back to the system: the positions array holds about the resident
    // points, not every point loaded so far (two partly shared pages per node at most).
    const SortedCloud& cloud = paged->cloud();
    const std::size_t positionPages =
        residentPages(cloud.positions().data(), cloud.capacity() * sizeof(glm::vec3));
    const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    const std::uint64_t residentPoints = stats.residentBytes / OmhPager::residentBytesPerPoint(reader.header());
    EXPECT_LE(positionPages, residentPoints * sizeof(glm::vec3) / page + 2 * stats.residentNodes);
    EXPECT_LT(positionPages, cloud.capacity() * sizeof(glm::vec3) / page);
}

TEST(OmhPagedLoad, UnderAPointBudgetOnlyWhatTheBudgetDrawsIsRead) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Random, 120000, 17), 6);
    OmhReader reader(path);
    const auto paged = openPaged(reader, std::uint64_t{1} << 30);
    Front front(paged);
    FrontOptions options = fullDetail();
    options.pointBudget = 10000;
    // Full detail is asked everywhere, the budget allows a twelfth of it: the front settles
    // at the budget and reads about what it draws, not every node it would like to refine.
    settlePaged(front, lookingAt({0.5, 0.5, 0.5}, 0.5, 1e9), options);
    std::uint64_t drawn = 0;
    for (const FrontEntry& entry : front.entries()) {
        drawn += paged->node(entry.level(), entry.index).pointCount;
    }
    EXPECT_LE(drawn, options.pointBudget);
    EXPECT_GT(drawn, options.pointBudget / 2);
    const std::uint64_t pointsRead = paged->residency()->stats().bytesRead / reader.header().recordBytes;
    EXPECT_LE(pointsRead, 3 * options.pointBudget) << "read " << pointsRead << " points";
}

TEST(OmhPagedLoad, AFrontMovingEveryFrameKeepsItsInvariantsWhileTheLoaderReads) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Plane, 80000, 13), 6);
    const auto whole = loadWhole(path);
    OmhReader reader(path);
    const auto paged = openPaged(reader, reader.residentBytesOfAllPoints() / 8);
    Front front(paged);
    // A camera sweeping across the cube, one evaluation per position, never waiting for the
    // loader: nodes arrive while the front moves on.
    for (int frame = 0; frame < 400; ++frame) {
        const double t = frame / 400.0;
        front.evaluate(lookingAt({t, 1.0 - t, 0.5}, 0.05 + 0.2 * t, 1e6), fullDetail());
        ASSERT_EQ(front.checkInvariants(), "") << "frame " << frame;
        ASSERT_NO_FATAL_FAILURE(expectFrontPointsEqual(front, *paged, *whole));
    }
    // However far the loader lagged behind (it may not even have run yet), the last view
    // fills in once the camera stops.
    const FrontCamera last = lookingAt({1.0, 0.0, 0.5}, 0.25, 1e6);
    settlePaged(front, last, fullDetail());
    expectFrontPointsEqual(front, *paged, *whole);
    EXPECT_GT(paged->residency()->stats().loads, 0u);
}

// Version 3 stores the deepest level's records last, version 4 its columns first.
class OmhPagedDamage : public ::testing::TestWithParam<std::uint32_t> {};
INSTANTIATE_TEST_SUITE_P(Versions, OmhPagedDamage, ::testing::Values(3u, 4u));

TEST_P(OmhPagedDamage, UnreadableRecordsFailTheirNodeOnlyAndTheParentStaysDrawn) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Random, 30000, 14), 5, GetParam());
    OmhReader reader(path);
    const auto paged = openPaged(reader, std::uint64_t{1} << 30);
    // The file loses its deepest level's records after it was opened (a disk unmounted, a
    // file replaced): those nodes cannot be read. Version 3: the file ends where they start;
    // version 4: its columns (before the node table) are overwritten with NaNs.
    const omh::Header& header = reader.header();
    const omh::LevelEntry& deepest = header.levels.back();
    ASSERT_EQ(header.columnar(deepest), GetParam() >= 4u);
    if (header.columnar(deepest)) {
        std::vector<std::uint8_t> bytes = readBytes(path);
        std::fill_n(bytes.begin() + static_cast<std::ptrdiff_t>(deepest.payloadOffset),
                    header.recordsBytes(deepest), std::uint8_t{0xff});
        writeBytes(path, bytes);
    } else {
        std::filesystem::resize_file(path, deepest.payloadOffset);
    }
    Front front(paged);
    settlePaged(front, lookingAt({0.5, 0.5, 0.5}, 0.5, 1e9), fullDetail());
    const ResidencyStats stats = paged->residency()->stats();
    EXPECT_GT(stats.failedNodes, 0u);
    EXPECT_NE(stats.firstError.find(path), std::string::npos) << stats.firstError;
    EXPECT_NE(stats.firstError.find("level " + std::to_string(paged->maxLevel())),
              std::string::npos)
        << stats.firstError;
    // Nothing of the deepest level is drawn; its parents are, in its place.
    for (const FrontEntry& entry : front.entries()) {
        EXPECT_LT(entry.level(), paged->maxLevel());
    }
    EXPECT_GT(front.entries().size(), 0u);
}

TEST(OmhPagedLoad, SavingAPagedHierarchyWritesTheSameBytesAndReplacingItsOwnFileWorks) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Random, 30000, 16), 5);
    const std::vector<std::uint8_t> original = readBytes(path);
    OmhReader reader(path);
    const auto paged = openPaged(reader, 4096);
    Front front(paged); // some nodes resident, most not: the save must not depend on it
    settlePaged(front, lookingAt({0.2, 0.2, 0.5}, 0.1, 1e9), fullDetail());
    const std::string copy = dir.file("copy.omh");
    writeOmh(copy, *paged, reader.header().build);
    EXPECT_EQ(readBytes(copy), original);
    // Saving over the file it pages from: the pager keeps reading the old file's data.
    writeOmh(path, *paged, reader.header().build);
    EXPECT_EQ(readBytes(path), original);
    settlePaged(front, lookingAt({0.8, 0.8, 0.5}, 0.1, 1e9), fullDetail());
    EXPECT_EQ(paged->residency()->stats().failedNodes, 0u);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
        ++files;
    }
    EXPECT_EQ(files, 2u) << "no temporary left";
    // A source that is gone is an error naming it; the target keeps its bytes.
    std::filesystem::remove(path);
    try {
        writeOmh(copy, *paged, reader.header().build);
        ADD_FAILURE() << "saving from a missing source succeeded";
    } catch (const std::exception& error) {
        EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    }
    EXPECT_EQ(readBytes(copy), original);
}

TEST(OmhPagedLoad, ThePipelineOpensAHierarchyLargerThanItsBudgetPaged) {
    TempDir dir;
    const std::string path = saveBuilt(dir, makeCloud(Shape::Random, 30000, 15), 5);
    BuildPipeline pipeline;
    PipelineOptions options;
    options.memoryBudgetBytes = 64 * 1024;
    const PipelineResult paged = pipeline.run(path, options);
    EXPECT_TRUE(paged.pagedPoints);
    EXPECT_NE(paged.pipeline.find("paged"), std::string::npos) << paged.pipeline;
    ASSERT_NE(pipeline.hierarchy(), nullptr);
    EXPECT_NE(pipeline.hierarchy()->residency(), nullptr);

    BuildPipeline resident;
    const PipelineResult whole = resident.run(path, PipelineOptions{});
    EXPECT_FALSE(whole.pagedPoints);
    EXPECT_EQ(resident.hierarchy()->residency(), nullptr);
}

} // namespace
} // namespace omicron::test
