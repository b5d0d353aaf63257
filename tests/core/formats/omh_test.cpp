// The .omh hierarchy file: bit-exact round trips of built hierarchies, the progressive
// level-by-level load, and detection of every damaged or truncated section.
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "hierarchy_test_support.hpp"
#include "io/input_error.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <thread>
#include <unistd.h>

namespace omicron::test {
namespace {

BuildOptions options(int depth, LeafCollapse collapse) {
    BuildOptions o;
    o.maxLevel = depth;
    o.collapse = collapse;
    return o;
}

void save(const std::string& path, const BuildResult& built,
          std::uint32_t formatVersion = omh::kVersion) {
    OmhWriteOptions options;
    options.formatVersion = formatVersion;
    writeOmh(path, built.builder->hierarchy(),
             omhBuildInfo(built.builder->options(), built.builder->statistics()), options);
}

std::shared_ptr<const Hierarchy> loadAll(const std::string& path) {
    OmhReader reader(path);
    auto hierarchy = reader.hierarchy();
    reader.load();
    return hierarchy;
}

template <typename T> bool sameBytes(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Everything a renderer reads, node by node and held point by held point, bit for bit.
void expectSameHierarchy(const Hierarchy& built, const Hierarchy& loaded) {
    ASSERT_EQ(built.maxLevel(), loaded.maxLevel());
    const SortedCloud& a = built.cloud();
    const SortedCloud& b = loaded.cloud();
    ASSERT_EQ(a.attributes(), b.attributes());
    EXPECT_EQ(b.order(), CloudOrder::NodeOrder);
    EXPECT_TRUE(sameBytes(a.cube(), b.cube()));
    EXPECT_TRUE(sameBytes(a.sourceOffset(), b.sourceOffset()));
    EXPECT_TRUE(loaded.publishedCut().complete);
    EXPECT_TRUE(b.complete());
    std::uint32_t nextLoadedPoint = 0;
    NodeSplats builtSplats, loadedSplats;
    SplatScratch scratch;
    for (int level = 0; level <= built.maxLevel(); ++level) {
        ASSERT_EQ(built.nodeCount(level), loaded.nodeCount(level)) << "level " << level;
        for (std::size_t i = 0; i < built.nodeCount(level); ++i) {
            const OctreeNode& x = built.node(level, i);
            const OctreeNode& y = loaded.node(level, i);
            ASSERT_EQ(x.code, y.code);
            ASSERT_EQ(x.pointCount, y.pointCount);
            ASSERT_EQ(x.firstChild, y.firstChild);
            ASSERT_EQ(x.childCount, y.childCount);
            ASSERT_EQ(x.flags, y.flags);
            ASSERT_TRUE(sameBytes(x.splatScale, y.splatScale));
            ASSERT_TRUE(y.holdsRange());
            ASSERT_EQ(y.coveredBegin, nextLoadedPoint) << "nodes hold consecutive ranges";
            ASSERT_EQ(y.coveredCount, y.pointCount);
            nextLoadedPoint += y.pointCount;
            // The file stores the built hierarchy's estimates (from version 3 only a sparse
            // node's) and the loaded node reads them back, or estimates them again from the
            // same points: the same bytes either way.
            built.nodeSplats(x, builtSplats, scratch);
            loaded.nodeSplats(y, loadedSplats, scratch);
            ASSERT_EQ(builtSplats.radii, loadedSplats.radii);
            ASSERT_EQ(builtSplats.normals, loadedSplats.normals);
            for (std::uint32_t p = 0; p < x.pointCount; ++p) {
                const std::uint32_t u = x.heldPoint(p), v = y.heldPoint(p);
                ASSERT_TRUE(sameBytes(a.positions()[u], b.positions()[v]));
                ASSERT_EQ(a.code(u), b.code(v));
                if (a.attributes().has(Attribute::Normal)) {
                    ASSERT_TRUE(sameBytes(a.normals()[u], b.normals()[v]));
                }
                if (a.attributes().has(Attribute::Color)) {
                    ASSERT_EQ(a.colors()[u], b.colors()[v]);
                }
                if (a.attributes().has(Attribute::Intensity)) {
                    ASSERT_EQ(a.intensities()[u], b.intensities()[v]);
                }
                const std::size_t lasBytes = a.attributes().lasBytes();
                if (lasBytes != 0) { // no LAS column: nothing to compare (and memcmp of null)
                    ASSERT_EQ(std::memcmp(a.lasRecord(u), b.lasRecord(v), lasBytes), 0)
                        << "the LAS fields of held point " << p;
                }
            }
        }
    }
    EXPECT_EQ(b.sortedEnd(), nextLoadedPoint);
}

// Build, save, load, compare, save again: the second file must equal the first.
void expectRoundTrip(const BuildResult& built, const TempDir& dir,
                     std::uint32_t formatVersion = omh::kVersion) {
    const std::string first = dir.file("first.omh");
    const std::string second = dir.file("second.omh");
    save(first, built, formatVersion);
    OmhReader reader(first);
    const auto loaded = reader.hierarchy();
    reader.load();
    ASSERT_NO_FATAL_FAILURE(expectSameHierarchy(built.builder->hierarchy(), *loaded));
    const BuildStatistics stats = built.builder->statistics();
    const omh::Header& header = reader.header();
    EXPECT_EQ(header.build.inputPoints, stats.inputPoints);
    EXPECT_EQ(header.build.droppedPoints, stats.droppedPoints);
    EXPECT_EQ(header.build.collapse, built.builder->options().collapse);
    for (std::size_t level = 0; level < stats.levels.size(); ++level) {
        EXPECT_EQ(header.levels[level].nodes, stats.levels[level].nodes);
        EXPECT_EQ(header.levels[level].leaves, stats.levels[level].leaves);
        EXPECT_EQ(header.levels[level].points, stats.levels[level].points);
    }
    OmhWriteOptions again;
    again.formatVersion = formatVersion;
    writeOmh(second, *loaded, header.build, again);
    EXPECT_EQ(readBytes(first), readBytes(second)) << "loading and saving again changed bytes";
}

// ---- Round trips ----

class OmhSharedFileRoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(OmhSharedFileRoundTrip, EveryCollapseModeIsBitExact) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    TempDir dir;
    for (LeafCollapse collapse : {LeafCollapse::Off, LeafCollapse::Lossless, LeafCollapse::Paper}) {
        SCOPED_TRACE(toString(collapse));
        const BuildResult built = buildFile(path, options(7, collapse));
        expectRoundTrip(built, dir);
    }
}

INSTANTIATE_TEST_SUITE_P(SharedData, OmhSharedFileRoundTrip,
                         ::testing::Values("bunny.ply", "dragon.ply", "lion.ply", "indoor.ply",
                                           "sorvilier.ply", "autzen_trim.ply", "autzen_trim.las",
                                           "laz/terrascan_fmt8.laz"));

// 4.8M points: one mode at a small depth keeps the suite fast on two cores.
TEST(OmhRoundTrip, AutzenSouthAtDepthFiveIsBitExact) {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_south.ply");
    TempDir dir;
    expectRoundTrip(buildFile(path, options(5, LeafCollapse::Paper)), dir);
}

TEST(OmhRoundTrip, SyntheticShapesInEveryModeAreBitExact) {
    TempDir dir;
    for (Shape shape : {Shape::Random, Shape::SinglePoint, Shape::AllIdentical, Shape::TwoClusters,
                        Shape::MaxFaces, Shape::Duplicates, Shape::Plane, Shape::Line}) {
        for (LeafCollapse collapse :
             {LeafCollapse::Off, LeafCollapse::Lossless, LeafCollapse::Paper}) {
            for (bool normals : {false, true}) {
                SCOPED_TRACE(std::string(toString(shape)) + ", " + toString(collapse) +
                             (normals ? ", normals" : ""));
                const BuildResult built =
                    buildSynthetic(makeCloud(shape, 3000, 7, normals), options(4, collapse));
                expectRoundTrip(built, dir);
            }
        }
    }
}

// The deep levels are written side by side in one sweep, a batch of subtrees at a time: the
// file does not depend on the batch size, from one point (every subtree alone, only the
// deepest level swept) to everything at once (the whole hierarchy one batch from the root),
// for a built hierarchy and for one loaded from the file.
TEST(OmhWriter, TheSweepsBatchSizeNeverChangesTheBytes) {
    OMICRON_REQUIRE_SHARED_FILE(path, "lion.ply");
    TempDir dir;
    const BuildResult built = buildFile(path, options(7, LeafCollapse::Lossless));
    const std::string reference = dir.file("reference.omh");
    save(reference, built);
    const auto loaded = loadAll(reference);
    const omh::BuildInfo info = omhBuildInfo(built.builder->options(), built.builder->statistics());
    for (const std::uint64_t batch : {std::uint64_t{1}, std::uint64_t{997}, std::uint64_t{60'000},
                                      std::uint64_t{1} << 40}) {
        SCOPED_TRACE(batch);
        OmhWriteOptions write;
        write.sweepBatchPoints = batch;
        std::vector<int> levelsWritten;
        write.afterLevel = [&](int level) { levelsWritten.push_back(level); };
        writeOmh(dir.file("built.omh"), built.builder->hierarchy(), info, write);
        EXPECT_EQ(readBytes(dir.file("built.omh")), readBytes(reference));
        std::sort(levelsWritten.begin(), levelsWritten.end());
        EXPECT_EQ(levelsWritten, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
        write.afterLevel = nullptr;
        writeOmh(dir.file("loaded.omh"), *loaded, info, write);
        EXPECT_EQ(readBytes(dir.file("loaded.omh")), readBytes(reference));
    }
}

TEST(OmhWriter, RefusesAnIncompleteHierarchyAndLeavesNothingBehind) {
    TempDir dir;
    const auto cloud =
        std::make_shared<SortedCloud>(CubeTransform{}, glm::dvec3(0.0), AttributeSet{}, 10);
    Hierarchy hierarchy(cloud, 3);
    omh::BuildInfo build;
    build.maxLevel = 3;
    EXPECT_THROW(writeOmh(dir.file("a.omh"), hierarchy, build), OutputError);
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// ---- Progressive load ----

TEST(OmhProgressiveLoad, LevelsArriveTopDownWhileAReaderWalksTheHierarchy) {
    TempDir dir;
    const BuildResult built =
        buildSynthetic(makeCloud(Shape::Random, 40000, 3), options(6, LeafCollapse::Off));
    const std::string path = dir.file("p.omh");
    save(path, built);

    OmhReader reader(path);
    const auto hierarchy = reader.hierarchy();
    std::vector<int> levels;
    std::atomic<bool> done{false};
    std::string readerProblem;
    // A front as the renderer runs it: from the root, into published children only.
    std::thread front([&] {
        while (!done.load()) {
            if (hierarchy->nodeCount(0) == 0) {
                continue;
            }
            if (!hierarchy->publishedCut().complete) {
                readerProblem = "level 0 published before the hierarchy was marked complete";
            }
            for (int level = 0; level < hierarchy->maxLevel(); ++level) {
                // Deeper first: a level seen published implies its parents are (acquire).
                const std::size_t nextCount = hierarchy->nodeCount(level + 1);
                const std::size_t count = hierarchy->nodeCount(level);
                const std::size_t cloudEnd = hierarchy->cloud().sortedEnd();
                for (std::size_t i = 0; i < count; ++i) {
                    const OctreeNode& node = hierarchy->node(level, i);
                    if (node.coveredBegin + node.pointCount > cloudEnd) {
                        readerProblem = "a published node's points are not published";
                    }
                    if (nextCount > 0 && node.firstChild + node.childCount > nextCount) {
                        readerProblem = "a level was published before all of its nodes";
                    }
                }
                if (count == 0 && nextCount != 0) {
                    readerProblem = "a level was published before its parents";
                }
            }
        }
    });
    reader.load([&](int level) { levels.push_back(level); });
    done.store(true);
    front.join();
    EXPECT_EQ(readerProblem, "");
    EXPECT_EQ(levels, (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
    expectSameHierarchy(built.builder->hierarchy(), *hierarchy);
}

TEST(OmhProgressiveLoad, CancelStopsBetweenLevels) {
    TempDir dir;
    const std::string path = dir.file("c.omh");
    save(path, buildSynthetic(makeCloud(Shape::Random, 5000, 5), options(5, LeafCollapse::Off)));
    OmhReader reader(path);
    const auto hierarchy = reader.hierarchy();
    std::atomic<bool> cancel{false};
    reader.load([&](int level) { cancel.store(level == 2); }, &cancel);
    EXPECT_GT(hierarchy->nodeCount(2), 0u);
    EXPECT_EQ(hierarchy->nodeCount(3), 0u);
    EXPECT_FALSE(hierarchy->cloud().complete());
}

// ---- Damage ----

// A small file whose every section is present (a few KiB, so flipping each byte stays fast).
struct SmallFile {
    TempDir dir;
    std::string path = dir.file("small.omh");
    std::vector<std::uint8_t> bytes;
    omh::Header header;

    explicit SmallFile(std::uint32_t version = omh::kVersion) {
        save(path, buildSynthetic(makeCloud(Shape::Random, 60, 11), options(2, LeafCollapse::Off)),
             version);
        bytes = readBytes(path);
        header = OmhReader(path).header();
    }

    // The words an error about byte `offset` must contain: a damaged byte, or (`cut`) the
    // file's end.
    std::string sectionName(std::uint64_t offset, bool cut = false) const {
        if (offset < omh::kHeaderBytes) {
            return "header";
        }
        const std::uint64_t tableEnd = omh::kHeaderBytes + header.levels.size() * 64 + 8;
        if (offset < tableEnd) {
            return "level table";
        }
        if (offset >= header.footerOffset()) {
            return "footer";
        }
        if (header.version >= 4) { // the deepest level's columns, each from a 4096-byte boundary
            if (offset < 4096) {
                return "padding after the level table";
            }
            const omh::LevelEntry& deepest = header.levels.back();
            const std::uint64_t points = deepest.points;
            // Positions (12 bytes a point) from 4096, then colours (3 bytes) from the next
            // boundary, then the sparse splat attributes from the one after.
            const std::uint64_t colors = (4096 + points * 12 + 4095) / 4096 * 4096;
            const std::uint64_t sparse = (colors + points * 3 + 4095) / 4096 * 4096;
            const std::string level = " of level " + std::to_string(header.levels.size() - 1);
            // A damaged byte in a column fails the level's checksum, which covers them all.
            if (offset < 4096 + points * 12) {
                return cut ? "position column" + level : "columns" + level;
            }
            if (offset < colors) {
                return "padding after the position column" + level;
            }
            if (offset < colors + points * 3) {
                return cut ? "colour column" + level : "columns" + level;
            }
            if (offset < sparse) {
                return "padding after the colour column" + level;
            }
            if (offset < sparse + deepest.sparsePoints * 6) {
                return "sparse nodes' splat attributes" + level;
            }
        }
        for (std::size_t l = header.levels.size(); l-- > 0;) {
            if (header.columnar(header.levels[l])) {
                continue;
            }
            if (offset >= header.sparseSplatsOffset(header.levels[l])) {
                // A damaged byte here fails the level's checksum, which names both parts.
                return "sparse nodes' splat attributes of level " + std::to_string(l);
            }
            if (offset >= header.levels[l].payloadOffset) {
                return "point records of level " + std::to_string(l);
            }
        }
        for (std::size_t l = header.levels.size(); l-- > 0;) {
            if (offset >= header.levels[l].nodeTableOffset) {
                return "node table of level " + std::to_string(l);
            }
        }
        return "?";
    }
};

// Opens and loads `path`; the InputError's message, or "" when nothing was detected.
std::string loadError(const std::string& path) {
    try {
        OmhReader reader(path);
        reader.load();
    } catch (const InputError& error) {
        return error.what();
    }
    return "";
}

// ---- Uniform columns (version 2) ----

// makeCloud's points with intensities and a LAS column (GPS time and `extraBytes` extra bytes):
// one value for every point where `uniformIntensity` / `uniformLas`, else varying.
SyntheticCloud withLasColumns(bool uniformIntensity, bool uniformLas,
                              std::uint16_t extraBytes = 0) {
    SyntheticCloud cloud = makeCloud(Shape::Random, 3000, 5);
    cloud.info.attributes.add(Attribute::Intensity).add(Attribute::Las).add(Attribute::GpsTime);
    cloud.info.attributes.setExtraBytes(extraBytes);
    cloud.points.attributes = cloud.info.attributes;
    const std::size_t lasBytes = cloud.info.attributes.lasBytes();
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        cloud.points.intensities.push_back(uniformIntensity ? 300 : static_cast<std::uint16_t>(i));
        for (std::size_t b = 0; b < lasBytes; ++b) {
            cloud.points.las.push_back(static_cast<std::uint8_t>(uniformLas ? b + 1 : i * 7 + b));
        }
    }
    return cloud;
}

TEST(OmhUniformColumns, AreStoredOnceInTheHeaderAndLoadBitExact) {
    TempDir dir;
    const std::size_t fullRecord =
        omh::RecordLayout::of(withLasColumns(false, false).info.attributes, true, 0, omh::kVersion)
            .bytes;
    for (const bool uniformIntensity : {false, true}) {
        for (const bool uniformLas : {false, true}) {
            SCOPED_TRACE(std::string(uniformIntensity ? "uniform" : "varying") + " intensity, " +
                         (uniformLas ? "uniform" : "varying") + " LAS column");
            const BuildResult built =
                buildSynthetic(withLasColumns(uniformIntensity, uniformLas), options(4, {}));
            ASSERT_EQ(built.cloud->uniformIntensities(), uniformIntensity);
            ASSERT_EQ(built.cloud->uniformLasColumn(), uniformLas);
            ASSERT_NO_FATAL_FAILURE(expectRoundTrip(built, dir));
            OmhReader reader(dir.file("first.omh"));
            const omh::Header& header = reader.header();
            EXPECT_EQ(header.version, omh::kVersion);
            EXPECT_EQ(header.uniformColumns, (uniformIntensity ? omh::kUniformIntensityBit : 0) |
                                                 (uniformLas ? omh::kUniformLasBit : 0));
            EXPECT_EQ(header.recordBytes,
                      fullRecord - (uniformIntensity ? 2 : 0) - (uniformLas ? 16 : 0));
            // Loaded (in memory, and paged on demand), the columns are uniform again.
            const auto loaded = loadAll(dir.file("first.omh"));
            EXPECT_EQ(loaded->cloud().uniformIntensities(), uniformIntensity);
            EXPECT_EQ(loaded->cloud().uniformLasColumn(), uniformLas);
            OmhReader paged(dir.file("first.omh"));
            paged.pageOnDemand(std::uint64_t{1} << 30);
            const auto pagedHierarchy = paged.hierarchy();
            paged.load();
            EXPECT_EQ(pagedHierarchy->cloud().uniformLasColumn(), uniformLas);
        }
    }
}

TEST(OmhUniformColumns, ALasRecordTooLongForTheHeaderStaysInTheRecords) {
    TempDir dir;
    // 8 + 8 GPS time + 100 extra bytes: more than the header's room.
    const BuildResult built = buildSynthetic(withLasColumns(true, true, 100), options(3, {}));
    ASSERT_GT(built.cloud->attributes().lasBytes(), omh::kMaxUniformLasBytes);
    ASSERT_TRUE(built.cloud->uniformLasColumn());
    ASSERT_NO_FATAL_FAILURE(expectRoundTrip(built, dir));
    EXPECT_EQ(OmhReader(dir.file("first.omh")).header().uniformColumns, omh::kUniformIntensityBit);
}

// `bytes` with header byte `at` set to `value` and the header checksum made right again.
std::vector<std::uint8_t> withHeaderByte(std::vector<std::uint8_t> bytes, std::size_t at,
                                         std::uint8_t value) {
    bytes[at] = value;
    const std::uint64_t checksum = omh::smallChecksum(bytes.data(), omh::header::kChecksum);
    std::memcpy(bytes.data() + omh::header::kChecksum, &checksum, sizeof checksum);
    return bytes;
}

TEST(OmhUniformColumns, AVersion1FileStillLoads) {
    TempDir dir;
    // Without uniform columns a version 2 file is a version 1 file but for its version.
    const BuildResult built = buildSynthetic(withLasColumns(false, false), options(4, {}));
    save(dir.file("v2.omh"), built, 2);
    const std::string v1 = dir.file("v1.omh");
    writeBytes(v1, withHeaderByte(readBytes(dir.file("v2.omh")), omh::header::kVersion, 1));
    OmhReader reader(v1);
    EXPECT_EQ(reader.header().version, 1u);
    const auto loaded = reader.hierarchy();
    reader.load();
    expectSameHierarchy(built.builder->hierarchy(), *loaded);
    // Version 1 had no uniform columns: its bytes 130-247 are reserved zeros.
    writeBytes(
        v1, withHeaderByte(readBytes(v1), omh::header::kUniformColumns, omh::kUniformIntensityBit));
    EXPECT_NE(loadError(v1).find("expected reserved bytes 130-247 to be zero"), std::string::npos)
        << loadError(v1);
}

// ---- Splat attributes out of the records (version 3) ----

// `bytes` with the level table of `levels` (its checksum made right) in place of theirs.
void putLevelTable(std::vector<std::uint8_t>& bytes, const std::vector<omh::LevelEntry>& levels,
                   std::uint32_t version) {
    const std::vector<std::uint8_t> table = omh::encodeLevelTable(levels, version);
    std::copy(table.begin(), table.end(), bytes.begin() + omh::kHeaderBytes);
}

// Points held by the nodes of `level` too sparse for an estimate of their own.
std::uint64_t sparsePointsOf(const Hierarchy& hierarchy, int level) {
    std::uint64_t points = 0;
    for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
        const std::uint32_t count = hierarchy.node(level, i).pointCount;
        points += count < kMinPointsPerSplatEstimate ? count : 0;
    }
    return points;
}

TEST(OmhVersion3, StoresSplatAttributesOnlyForSparseNodesAndLoadsTheBuildsBitForBit) {
    TempDir dir;
    for (const bool normals : {false, true}) {
        SCOPED_TRACE(normals ? "with normals" : "estimated normals");
        const SyntheticCloud cloud = makeCloud(Shape::Plane, 20000, 17, normals);
        const BuildResult built = buildSynthetic(cloud, options(5, {}));
        const Hierarchy& hierarchy = built.builder->hierarchy();
        ASSERT_NO_FATAL_FAILURE(expectRoundTrip(built, dir, 3));
        const omh::Header header = OmhReader(dir.file("first.omh")).header();
        EXPECT_EQ(header.version, 3u);
        EXPECT_FALSE(header.splatsInRecords());
        EXPECT_EQ(header.estimatedNormals, !normals);
        EXPECT_EQ(header.recordBytes, oms::RecordLayout::of(header.attributes).bytes);
        std::uint64_t sparse = 0;
        for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
            const omh::LevelEntry& entry = header.levels[static_cast<std::size_t>(level)];
            EXPECT_EQ(entry.sparsePoints, sparsePointsOf(hierarchy, level)) << "level " << level;
            sparse += entry.sparsePoints;
        }
        ASSERT_GT(sparse, 0u) << "no sparse node: the stored attributes went untested";
        ASSERT_LT(sparse, header.totalPoints / 10) << "most nodes are estimated again";
        EXPECT_EQ(readBytes(dir.file("first.omh")).size(),
                  omh::kHeaderBytes + header.levels.size() * 64 + 8 +
                      header.totalNodes * omh::kNodeRecordBytes +
                      header.totalPoints * header.recordBytes + sparse * (normals ? 2u : 6u) +
                      omh::kFooterBytes);
    }
}

TEST(OmhVersion3, AVersion2FileStillLoadsWithTheSplatAttributesItsRecordsCarry) {
    TempDir dir;
    const BuildResult built = buildSynthetic(withLasColumns(false, true), options(5, {}));
    save(dir.file("v2.omh"), built, 2);
    save(dir.file("v3.omh"), built);
    OmhReader reader(dir.file("v2.omh"));
    const omh::Header& v2 = reader.header();
    EXPECT_EQ(v2.version, 2u);
    EXPECT_TRUE(v2.splatsInRecords());
    const omh::Header v3 = OmhReader(dir.file("v3.omh")).header();
    EXPECT_EQ(v2.recordBytes, v3.recordBytes + v3.splatBytes());
    for (const omh::LevelEntry& level : v2.levels) {
        EXPECT_EQ(level.sparsePoints, 0u);
    }
    const auto loaded = reader.hierarchy();
    reader.load();
    ASSERT_NO_FATAL_FAILURE(expectSameHierarchy(built.builder->hierarchy(), *loaded));
    // Saved again, a version 2 file becomes the version 3 file of the same hierarchy.
    writeOmh(dir.file("again.omh"), *loaded, v2.build);
    EXPECT_EQ(readBytes(dir.file("again.omh")), readBytes(dir.file("v3.omh")));
    // Its splat attributes are what it stores, not an estimate: a changed radius is drawn.
    std::vector<std::uint8_t> bytes = readBytes(dir.file("v2.omh"));
    const omh::LevelEntry& deepest = v2.levels.back();
    const std::uint64_t radius =
        deepest.payloadOffset +
        omh::RecordLayout::of(v2.attributes, v2.estimatedNormals, v2.uniformColumns, 2)
            .radiusOffset;
    bytes[radius] ^= 0x01;
    // The level's checksum, made right again.
    oms::PayloadChecksum checksum;
    checksum.update(bytes.data() + deepest.payloadOffset, v2.payloadBytes(deepest));
    std::vector<omh::LevelEntry> levels = v2.levels;
    levels.back().payloadChecksum = checksum.digest();
    putLevelTable(bytes, levels, 2);
    writeBytes(dir.file("changed.omh"), bytes);
    const auto changedLoad = loadAll(dir.file("changed.omh"));
    const Hierarchy& original = built.builder->hierarchy();
    const int level = original.maxLevel();
    NodeSplats a, b;
    SplatScratch scratch;
    original.nodeSplats(original.node(level, 0), a, scratch);
    changedLoad->nodeSplats(changedLoad->node(level, 0), b, scratch);
    ASSERT_FALSE(a.radii.empty());
    EXPECT_EQ(b.radii[0], a.radii[0] ^ 0x01);
}

TEST(OmhVersion3, ASparseNodeCountThatDisagreesWithTheNodeTableIsAClearError) {
    SmallFile file(3);
    std::size_t level = 0;
    while (level < file.header.levels.size() && file.header.levels[level].sparsePoints == 0) {
        ++level;
    }
    ASSERT_LT(level, file.header.levels.size()) << "the small file has no sparse node";
    // One point fewer declared sparse, its attributes dropped and the offsets after them moved
    // (and the level table's checksum made right): the file's size agrees with its level
    // table, and only the node table disagrees.
    std::vector<omh::LevelEntry> levels = file.header.levels;
    levels[level].sparsePoints -= 1;
    for (std::size_t l = level + 1; l < levels.size(); ++l) {
        levels[l].payloadOffset -= file.header.splatBytes();
    }
    std::vector<std::uint8_t> bytes = file.bytes;
    const std::uint64_t cut = file.header.sparseSplatsOffset(file.header.levels[level]);
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(cut),
                bytes.begin() + static_cast<std::ptrdiff_t>(cut + file.header.splatBytes()));
    putLevelTable(bytes, levels, 3);
    const std::string bad = file.dir.file("bad.omh");
    writeBytes(bad, bytes);
    const std::string message = loadError(bad);
    EXPECT_NE(message.find(bad), std::string::npos) << message;
    EXPECT_NE(message.find("the nodes of fewer than 8 points hold"), std::string::npos) << message;
}

TEST(OmhUniformColumns, BadUniformFieldsAreClearErrors) {
    TempDir dir;
    save(dir.file("uniform.omh"), buildSynthetic(withLasColumns(true, true), options(3, {})));
    save(dir.file("plain.omh"), buildSynthetic(makeCloud(Shape::Random, 500, 3), options(3, {})));
    const std::vector<std::uint8_t> uniform = readBytes(dir.file("uniform.omh"));
    const std::vector<std::uint8_t> plain = readBytes(dir.file("plain.omh"));
    const std::string bad = dir.file("bad.omh");
    const auto expectError = [&](const std::vector<std::uint8_t>& bytes, const std::string& words) {
        writeBytes(bad, bytes);
        const std::string message = loadError(bad);
        EXPECT_NE(message.find(bad), std::string::npos) << message;
        EXPECT_NE(message.find(words), std::string::npos) << message;
    };
    expectError(withHeaderByte(uniform, omh::header::kUniformColumns, 0x07),
                "unknown uniform column bits");
    expectError(withHeaderByte(plain, omh::header::kUniformColumns, omh::kUniformIntensityBit),
                "the cloud has no intensities");
    expectError(withHeaderByte(plain, omh::header::kUniformColumns, omh::kUniformLasBit),
                "a uniform LAS column is declared");
    expectError(withHeaderByte(plain, omh::header::kReserved2, 1), "reserved zero byte");
    expectError(withHeaderByte(plain, omh::header::kVersion, 5), "format version 1 to 4, found 5");
    // The uniform LAS record ends at byte 134 + 16: a byte after it must be zero.
    expectError(withHeaderByte(uniform, omh::header::kUniformLasRecord + 16, 9),
                "expected reserved bytes 150-247 to be zero");
}

// Each version's layout: 3 stores every level as records, 4 the deepest as columns first.
class OmhDamage : public ::testing::TestWithParam<std::uint32_t> {};
INSTANTIATE_TEST_SUITE_P(Versions, OmhDamage, ::testing::Values(3u, 4u));

TEST_P(OmhDamage, EveryByteFlipIsDetectedAndNamesTheSection) {
    SmallFile file(GetParam());
    ASSERT_EQ(file.header.version, GetParam());
    ASSERT_GT(file.header.levels[2].points, 0u);
    const std::string damaged = file.dir.file("damaged.omh");
    for (std::size_t at = 0; at < file.bytes.size(); ++at) {
        std::vector<std::uint8_t> bytes = file.bytes;
        bytes[at] ^= 0x5a;
        writeBytes(damaged, bytes);
        const std::string message = loadError(damaged);
        ASSERT_NE(message, "") << "flip at byte " << at << " went unnoticed";
        ASSERT_NE(message.find(damaged), std::string::npos) << message;
        ASSERT_NE(message.find(file.sectionName(at)), std::string::npos)
            << "byte " << at << ": " << message;
    }
}

TEST_P(OmhDamage, VerifyFindsAFlipThatOpeningDoesNotRead) {
    SmallFile file(GetParam());
    std::vector<std::uint8_t> bytes = file.bytes;
    bytes[file.header.levels[2].payloadOffset + 1] ^= 1;
    writeBytes(file.path, bytes);
    OmhReader reader(file.path); // header, level table and footer are intact
    try {
        reader.verify();
        FAIL() << "verify() missed the damaged point records";
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what())
                      .find(file.sectionName(file.header.levels[2].payloadOffset + 1)),
                  std::string::npos)
            << error.what();
    }
}

TEST_P(OmhDamage, TruncationAtEverySectionBoundaryIsAClearError) {
    SmallFile file(GetParam());
    std::vector<std::uint64_t> boundaries{1, omh::kHeaderBytes, file.header.nodeTableOffset(),
                                          file.header.footerOffset(), file.bytes.size() - 1};
    for (const omh::LevelEntry& level : file.header.levels) {
        boundaries.push_back(level.nodeTableOffset);
        boundaries.push_back(level.payloadOffset);
        if (level.sparsePoints > 0) {
            boundaries.push_back(file.header.sparseSplatsOffset(level));
        }
    }
    const std::string cut = file.dir.file("cut.omh");
    for (std::uint64_t size : boundaries) {
        writeBytes(cut, std::vector<std::uint8_t>(file.bytes.begin(), file.bytes.begin() + size));
        try {
            OmhReader reader(cut);
            FAIL() << "a file cut at byte " << size << " opened";
        } catch (const InputError& error) {
            const std::string message = error.what();
            EXPECT_EQ(error.kind(), InputErrorKind::Truncated) << message;
            EXPECT_NE(message.find(cut), std::string::npos) << message;
            EXPECT_NE(message.find(file.sectionName(size, true)), std::string::npos)
                << "cut at " << size << ": " << message;
        }
    }
    writeBytes(cut, {});
    try {
        OmhReader reader(cut);
        FAIL() << "an empty file opened";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::EmptyFile);
    }
}

TEST_P(OmhDamage, TrailingBytesAreACountMismatch) {
    SmallFile file(GetParam());
    std::vector<std::uint8_t> bytes = file.bytes;
    bytes.push_back(0);
    writeBytes(file.path, bytes);
    try {
        OmhReader reader(file.path);
        FAIL();
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::CountMismatch) << error.what();
    }
}

// ---- Safe save ----

TEST(OmhSafeSave, AFailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
    TempDir dir;
    const std::string path = dir.file("keep.omh");
    const BuildResult small =
        buildSynthetic(makeCloud(Shape::Random, 500, 1), options(3, LeafCollapse::Off));
    save(path, small);
    const std::vector<std::uint8_t> before = readBytes(path);
    const BuildResult large =
        buildSynthetic(makeCloud(Shape::Random, 200000, 2), options(6, LeafCollapse::Off));

    // A file size limit makes write() fail with EFBIG part way, as a full disk fails it with
    // ENOSPC: the same error path.
    rlimit previous{};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &previous), 0);
    const auto previousHandler = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limited = previous;
    limited.rlim_cur = 1 << 20;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
    std::string message;
    try {
        save(path, large);
    } catch (const OutputError& error) {
        message = error.what();
    }
    setrlimit(RLIMIT_FSIZE, &previous);
    std::signal(SIGXFSZ, previousHandler);

    EXPECT_NE(message.find(path), std::string::npos) << "the error names the file: " << message;
    EXPECT_EQ(readBytes(path), before);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
        ++files;
    }
    EXPECT_EQ(files, 1u) << "no temporary file is left behind";
    EXPECT_NO_THROW(loadAll(path));
}

TEST(OmhSafeSave, AMissingOrUnwritableFolderIsAnOutputErrorNamingTheFile) {
    TempDir dir;
    const BuildResult built =
        buildSynthetic(makeCloud(Shape::Random, 100, 1), options(2, LeafCollapse::Off));
    const std::string missing = dir.file("no-such-folder/a.omh");
    try {
        save(missing, built);
        FAIL();
    } catch (const OutputError& error) {
        EXPECT_NE(std::string(error.what()).find(missing), std::string::npos);
    }
    if (geteuid() != 0) { // root writes into read-only folders
        const std::filesystem::path locked = dir.path() / "locked";
        std::filesystem::create_directory(locked);
        std::filesystem::permissions(locked, std::filesystem::perms::owner_read |
                                                 std::filesystem::perms::owner_exec);
        EXPECT_THROW(save((locked / "a.omh").string(), built), OutputError);
        std::filesystem::permissions(locked, std::filesystem::perms::owner_all);
    }
}

TEST(OmhDetection, IsOmhFileChecksTheMagicOrTheExtension) {
    SmallFile file;
    const std::string renamed = file.dir.file("hierarchy.bin");
    std::filesystem::copy_file(file.path, renamed);
    EXPECT_TRUE(isOmhFile(file.path));
    EXPECT_TRUE(isOmhFile(renamed));
    EXPECT_TRUE(isOmhFile(file.dir.file("missing.OMH")));
    EXPECT_FALSE(isOmhFile(file.dir.file("missing.ply")));
}

} // namespace
} // namespace omicron::test
