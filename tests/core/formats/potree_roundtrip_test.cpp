// The Potree export read back by an independent reader written from the Potree 2.0 format's
// description (metadata.json; hierarchy.bin: 22-byte records type u8, childMask u8,
// numPoints u32, byteOffset u64, byteSize u64 in chunks, a proxy pointing at its chunk;
// octree.bin: the records of the attributes metadata.json lists, positions int32 x 3 x scale
// + offset), and compared with the input: the multiset of decoded points equals the input's
// (positions within one quantisation step of 2^-30 of the edge, colour and intensity exact),
// each point once. Runs on generated clouds, on a loaded .omh (whose nodes hold copies), and on
// every shared scan.
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "formats/potree_writer.hpp"
#include "hierarchy_test_support.hpp"
#include "std_regex.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <gtest/gtest.h>
#include <tuple>

namespace omicron::test {
namespace {

// ---- The independent reader ----

struct DecodedPoint {
    std::array<std::int32_t, 3> stored{};
    std::array<double, 3> position{};
    std::array<std::uint16_t, 3> rgb{};
    std::uint16_t intensity = 0;
};

struct PotreeFolder {
    std::uint64_t declaredPoints = 0;
    std::uint64_t nodes = 0;
    std::vector<DecodedPoint> points;
};

template <typename T> T le(const std::uint8_t* at) {
    T value;
    std::memcpy(&value, at, sizeof(T));
    return value;
}

std::array<double, 3> jsonTriple(const std::string& json, const std::string& key) {
    const std::string number = R"(\s*([-+0-9.eE]+)\s*)";
    std::smatch m;
    const bool found = std::regex_search(
        json, m, std::regex("\"" + key + R"("\s*:\s*\[)" + number + "," + number + "," + number));
    EXPECT_TRUE(found) << key;
    return found ? std::array<double, 3>{std::stod(m[1]), std::stod(m[2]), std::stod(m[3])}
                 : std::array<double, 3>{};
}

std::uint64_t jsonInteger(const std::string& json, const std::string& key) {
    std::smatch m;
    const bool found = std::regex_search(json, m, std::regex("\"" + key + R"("\s*:\s*(\d+))"));
    EXPECT_TRUE(found) << key;
    return found ? std::stoull(m[1]) : 0;
}

PotreeFolder readPotreeFolder(const std::string& folder) {
    const auto metadataBytes = readBytes(folder + "/metadata.json");
    const std::string json(metadataBytes.begin(), metadataBytes.end());
    const auto hierarchy = readBytes(folder + "/hierarchy.bin");
    const auto octree = readBytes(folder + "/octree.bin");
    PotreeFolder result;
    result.declaredPoints = jsonInteger(json, "points");
    const auto scale = jsonTriple(json, "scale");
    const auto offset = jsonTriple(json, "offset");
    // The record: attributes in the order listed, each "size" bytes.
    std::vector<std::pair<std::string, std::size_t>> attributes;
    const std::regex attribute(R"re("name"\s*:\s*"([^"]+)"[^}]*?"size"\s*:\s*(\d+))re");
    const std::size_t listStart = json.find("\"attributes\"");
    for (auto it = std::sregex_iterator(json.begin() + static_cast<long>(listStart), json.end(),
                                        attribute);
         it != std::sregex_iterator(); ++it) {
        attributes.emplace_back((*it)[1], std::stoul((*it)[2]));
    }
    std::size_t recordBytes = 0;
    for (const auto& a : attributes) {
        recordBytes += a.second;
    }
    // Chunks: the first one is firstChunkSize bytes at 0; a proxy record gives its chunk.
    std::deque<std::pair<std::uint64_t, std::uint64_t>> chunks{
        {0, jsonInteger(json, "firstChunkSize")}};
    while (!chunks.empty()) {
        const auto [chunkOffset, chunkSize] = chunks.front();
        chunks.pop_front();
        EXPECT_LE(chunkOffset + chunkSize, hierarchy.size());
        for (std::uint64_t at = chunkOffset; at + 22 <= chunkOffset + chunkSize; at += 22) {
            const std::uint8_t* record = hierarchy.data() + at;
            const auto numPoints = le<std::uint32_t>(record + 2);
            const auto byteOffset = le<std::uint64_t>(record + 6);
            const auto byteSize = le<std::uint64_t>(record + 14);
            if (record[0] == 2) { // proxy: its own record opens the chunk it points to
                chunks.emplace_back(byteOffset, byteSize);
                continue;
            }
            ++result.nodes;
            EXPECT_EQ(byteSize, std::uint64_t{numPoints} * recordBytes);
            EXPECT_LE(byteOffset + byteSize, octree.size());
            for (std::uint32_t p = 0; p < numPoints; ++p) {
                const std::uint8_t* point = octree.data() + byteOffset + p * recordBytes;
                DecodedPoint decoded;
                for (const auto& [name, size] : attributes) {
                    if (name == "position") {
                        for (int axis = 0; axis < 3; ++axis) {
                            decoded.stored[axis] = le<std::int32_t>(point + 4 * axis);
                            decoded.position[axis] =
                                decoded.stored[axis] * scale[axis] + offset[axis];
                        }
                    } else if (name == "rgb") {
                        for (int c = 0; c < 3; ++c) {
                            decoded.rgb[c] = le<std::uint16_t>(point + 2 * c);
                        }
                    } else if (name == "intensity") {
                        decoded.intensity = le<std::uint16_t>(point);
                    }
                    point += size;
                }
                result.points.push_back(decoded);
            }
        }
    }
    return result;
}

// ---- The comparison ----

using Key = std::tuple<std::int32_t, std::int32_t, std::int32_t, std::uint16_t, std::uint16_t,
                       std::uint16_t, std::uint16_t>;

Key key(const DecodedPoint& p) {
    return {p.stored[0], p.stored[1], p.stored[2], p.rgb[0], p.rgb[1], p.rgb[2], p.intensity};
}

// The input points of `cloud` (as the reader delivered them) quantised to the export's grid:
// floor(unit x 2^30), the step a point's exported position must fall in.
std::vector<DecodedPoint> expectedPoints(const SortedCloud& cloud) {
    std::vector<DecodedPoint> points(cloud.sortedEnd());
    const CubeTransform& cube = cloud.cube();
    for (std::size_t i = 0; i < points.size(); ++i) {
        const glm::vec3 unit = cloud.position(i);
        for (int axis = 0; axis < 3; ++axis) {
            const double steps = std::floor(double(unit[axis]) * double(1u << 30));
            points[i].stored[axis] =
                static_cast<std::int32_t>(std::clamp(steps, 0.0, double((1u << 30) - 1)));
            points[i].position[axis] =
                cube.origin[axis] + double(unit[axis]) * cube.edge + cloud.sourceOffset()[axis];
        }
        if (cloud.attributes().has(Attribute::Color)) {
            for (int c = 0; c < 3; ++c) {
                points[i].rgb[c] = static_cast<std::uint16_t>(cloud.color(i)[c] * 257);
            }
        }
        if (cloud.attributes().has(Attribute::Intensity)) {
            points[i].intensity = cloud.intensities()[i];
        }
    }
    return points;
}

// The decoded multiset equals `expected` (or is contained in it, for a paper collapse).
void expectSameMultiset(std::vector<DecodedPoint> decoded, std::vector<DecodedPoint> expected,
                        double scale, double tolerance, bool subset = false) {
    if (!subset) {
        ASSERT_EQ(decoded.size(), expected.size());
    }
    const auto byKey = [](const DecodedPoint& a, const DecodedPoint& b) {
        return key(a) < key(b);
    };
    std::sort(decoded.begin(), decoded.end(), byKey);
    std::sort(expected.begin(), expected.end(), byKey);
    std::size_t e = 0, mismatches = 0;
    for (const DecodedPoint& d : decoded) {
        while (subset && e < expected.size() && byKey(expected[e], d)) {
            ++e;
        }
        if (e == expected.size() || key(expected[e]) != key(d)) {
            ++mismatches;
            continue;
        }
        for (int axis = 0; axis < 3; ++axis) {
            // Within one step below the input (the floor) and the stated tolerance.
            ASSERT_LE(d.position[axis], expected[e].position[axis] + 1e-9 * scale * (1 << 30));
            ASSERT_GE(d.position[axis],
                      expected[e].position[axis] - scale * (1 + 1e-6) - 1e-9 * scale * (1 << 30));
            ASSERT_LE(std::abs(d.position[axis] - expected[e].position[axis]), tolerance);
        }
        ++e;
    }
    EXPECT_EQ(mismatches, 0u) << "decoded points that are not input points";
}

void expectRoundTrip(const Hierarchy& hierarchy, const SortedCloud& input,
                     const PotreeExportSummary& summary, const std::string& folder) {
    const PotreeFolder read = readPotreeFolder(folder);
    EXPECT_EQ(read.declaredPoints, summary.points);
    EXPECT_EQ(read.points.size(), summary.points);
    EXPECT_EQ(read.nodes, summary.nodes);
    EXPECT_EQ(summary.points + summary.droppedPoints, input.sortedEnd());
    const double scale = input.cube().edge / double(1u << 30);
    expectSameMultiset(read.points, expectedPoints(input), scale, summary.positionTolerance,
                       summary.droppedPoints > 0);
    (void)hierarchy;
}

TEST(PotreeRoundTrip, GeneratedCloudsEveryPointOnce) {
    struct Case {
        Shape shape;
        std::size_t points;
        int depth;
        double ratio;
        LeafCollapse collapse;
        PointStorage storage;
    };
    for (const Case& c :
         {Case{Shape::Random, 30000, 6, 0.2, LeafCollapse::Off, PointStorage::Exact},
          Case{Shape::Random, 30000, 8, 0.5, LeafCollapse::Lossless, PointStorage::Exact},
          Case{Shape::Random, 20000, 5, 1.0, LeafCollapse::Off, PointStorage::Packed},
          Case{Shape::AllIdentical, 5000, 4, 0.2, LeafCollapse::Off, PointStorage::Exact},
          Case{Shape::SinglePoint, 1, 3, 0.2, LeafCollapse::Off, PointStorage::Exact}}) {
        SCOPED_TRACE(testing::Message()
                     << "points " << c.points << " depth " << c.depth << " ratio " << c.ratio);
        TempDir dir;
        BuildOptions options;
        options.maxLevel = c.depth;
        options.ratio = c.ratio;
        options.collapse = c.collapse;
        const BuildResult built =
            buildSynthetic(makeCloud(c.shape, c.points, 5), options, 4096, 8, c.storage);
        const PotreeExportSummary summary =
            exportPotree(built.builder->hierarchy(), dir.file("potree"));
        EXPECT_EQ(summary.points, built.cloud->sortedEnd());
        EXPECT_EQ(summary.droppedPoints, 0u);
        expectRoundTrip(built.builder->hierarchy(), *built.cloud, summary, dir.file("potree"));
    }
}

TEST(PotreeRoundTrip, PaperCollapseStatesWhatItDropped) {
    TempDir dir;
    BuildOptions options;
    options.maxLevel = 9;
    options.collapse = LeafCollapse::Paper;
    const BuildResult built = buildSynthetic(makeCloud(Shape::Random, 30000, 3), options);
    const PotreeExportSummary summary =
        exportPotree(built.builder->hierarchy(), dir.file("potree"));
    EXPECT_GT(summary.droppedPoints, 0u);
    EXPECT_EQ(summary.droppedPoints, built.builder->statistics().droppedPoints);
    expectRoundTrip(built.builder->hierarchy(), *built.cloud, summary, dir.file("potree"));
    const auto metadata = readBytes(dir.file("potree") + "/metadata.json");
    EXPECT_NE(std::string(metadata.begin(), metadata.end())
                  .find(std::to_string(summary.droppedPoints) + " dropped"),
              std::string::npos);
}

// A loaded .omh stores every node's points apart, parents' copies included: the export finds
// the copies by their records and still stores each input point once.
TEST(PotreeRoundTrip, LoadedHierarchyFileEveryPointOnce) {
    TempDir dir;
    BuildOptions options;
    options.maxLevel = 6;
    const BuildResult built = buildSynthetic(makeCloud(Shape::Random, 25000, 11), options);
    writeOmh(dir.file("a.omh"), built.builder->hierarchy(),
             omhBuildInfo(options, built.builder->statistics()));
    OmhReader reader(dir.file("a.omh"));
    const auto loaded = reader.hierarchy();
    reader.load();
    PotreeExportOptions exportOptions;
    exportOptions.inputPoints = reader.header().build.inputPoints;
    const PotreeExportSummary summary = exportPotree(*loaded, dir.file("potree"), exportOptions);
    EXPECT_EQ(summary.points, built.cloud->sortedEnd());
    expectRoundTrip(*loaded, *built.cloud, summary, dir.file("potree"));
}

class PotreeRoundTripShared : public testing::TestWithParam<std::string> {};

TEST_P(PotreeRoundTripShared, EveryInputPointOnce) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    TempDir dir;
    const BuildResult built = buildFile(path, BuildOptions{});
    const PotreeExportSummary summary =
        exportPotree(built.builder->hierarchy(), dir.file("potree"));
    EXPECT_EQ(summary.points, built.cloud->sortedEnd()) << "every input point, once";
    expectRoundTrip(built.builder->hierarchy(), *built.cloud, summary, dir.file("potree"));
}

INSTANTIATE_TEST_SUITE_P(SharedScans, PotreeRoundTripShared,
                         testing::Values("bunny.ply", "dragon.ply", "lion.ply", "sorvilier.ply",
                                         "indoor.ply", "autzen_trim.ply", "autzen_trim.las",
                                         "autzen_south.ply"),
                         FileParamName{});

} // namespace
} // namespace omicron::test
