// Sorting beyond the memory budget: under a budget that forces runs on disk, the sorter emits
// point for point what the in-memory sort emits (real scans and adversarial clouds), and its
// scratch files, which have no names, are closed after success, a reader failure, a cancel and
// a full disk.
#include "io/input_error.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "memory_budget.hpp"
#include "run_process.hpp"
#include "sort/morton_sorter.hpp"
#include "test_files.hpp"

#include <csignal>
#include <filesystem>
#include <functional>
#include <gtest/gtest.h>
#include <random>
#include <sys/resource.h>
#include <vector>

namespace omicron {
namespace {

// Everything a sort emitted, and how it ran.
struct Sorted {
    PointBatch points;
    bool spilled = false;
    std::size_t runs = 0;
    bool complete = false;
};

Sorted sortFile(const std::string& path, const SortOptions& options) {
    auto reader = openPointCloud(path);
    Sorted result;
    result.points.attributes = reader->info().attributes;
    std::size_t expectedBegin = 0;
    std::shared_ptr<const SortedCloud> cloud;
    sortPointCloud(
        *reader, options,
        [&](const SortedCloud& sorted, std::size_t begin, std::size_t end) {
            EXPECT_EQ(begin, expectedBegin);
            EXPECT_LE(end, sorted.sortedEnd());
            expectedBegin = end;
            PointBatch range;
            sorted.copyRange(begin, end, range);
            result.points.append(range);
        },
        [&](const IncrementalMortonSorter& sorter) {
            result.spilled = sorter.spills();
            cloud = sorter.cloud();
        });
    result.complete = cloud->complete();
    return result;
}

void expectSamePoints(const PointBatch& a, const PointBatch& b) {
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.attributes, b.attributes);
    std::size_t differences = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const bool same = a.positions[i] == b.positions[i] &&
                          (a.colors.empty() || a.colors[i] == b.colors[i]) &&
                          (a.normals.empty() || a.normals[i] == b.normals[i]) &&
                          (a.intensities.empty() || a.intensities[i] == b.intensities[i]);
        differences += same ? 0 : 1;
    }
    EXPECT_EQ(differences, 0u);
    EXPECT_TRUE(a.las == b.las) << "the LAS fields were not carried through the runs";
}

std::size_t entriesIn(const std::filesystem::path& folder) {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(folder), {}));
}

// A PLY of `count` points in few distinct places (many exact duplicates, long equal-code runs
// across run boundaries), each point's colour its input index, so any reordering of equal
// codes shows.
std::string writeAdversarialCloud(const test::TempDir& dir, std::size_t count) {
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Intensity) | Attribute::Color;
    std::mt19937 random(3);
    for (std::size_t i = 0; i < count; ++i) {
        const float cell = float(random() % 5) / 4.0f;
        batch.positions.emplace_back(cell, 0.5f, i % 3 == 0 ? 1.0f : cell);
        batch.colors.emplace_back(i & 0xff, (i >> 8) & 0xff, (i >> 16) & 0xff);
        batch.intensities.push_back(static_cast<std::uint16_t>(i));
    }
    batch.positions[0] = glm::vec3(0.0f);
    const std::string path = dir.file("adversarial.ply");
    writePly(path, batch, CubeTransform{glm::dvec3(0.0), 10.0});
    return path;
}

// The smallest budget: every cloud here spills, into `scratch`.
// Runs `run` with files limited to `limitBytes` (RLIMIT_FSIZE, SIGXFSZ ignored: a write beyond
// it fails with EFBIG, as on a full disk) and returns the OutputError it threw ("" if none).
std::string outputErrorUnderFileSizeLimit(rlim_t limitBytes, const std::function<void()>& run) {
    rlimit previous{};
    if (getrlimit(RLIMIT_FSIZE, &previous) != 0) {
        ADD_FAILURE() << "getrlimit(RLIMIT_FSIZE) failed";
        return {};
    }
    const auto previousHandler = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limited = previous;
    limited.rlim_cur = limitBytes;
    std::string message;
    if (setrlimit(RLIMIT_FSIZE, &limited) != 0) {
        ADD_FAILURE() << "setrlimit(RLIMIT_FSIZE) failed";
    } else {
        try {
            run();
        } catch (const OutputError& error) {
            message = error.what();
        }
    }
    setrlimit(RLIMIT_FSIZE, &previous);
    std::signal(SIGXFSZ, previousHandler);
    return message;
}

SortOptions spillingOptions(const test::TempDir& scratch) {
    SortOptions options;
    options.memoryBudgetBytes = kMinMemoryBudget;
    options.tempDir = scratch.path().string();
    return options;
}

class ExternalSort : public testing::TestWithParam<std::string> {};

TEST_P(ExternalSort, RunsOnDiskGiveThePointsOfTheInMemorySort) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    test::TempDir scratch;
    const Sorted inMemory = sortFile(path, SortOptions{});
    ASSERT_FALSE(inMemory.spilled);
    const SortOptions spilling = spillingOptions(scratch);
    const Sorted external = sortFile(path, spilling);
    EXPECT_TRUE(external.spilled);
    EXPECT_TRUE(external.complete);
    expectSamePoints(external.points, inMemory.points);
    EXPECT_EQ(entriesIn(scratch.path()), 0u) << "the runs outlived the sort";
    EXPECT_EQ(test::openFilesIn(0, scratch.path()).size(), 0u) << "the runs outlived the sort";
}

INSTANTIATE_TEST_SUITE_P(Files, ExternalSort,
                         testing::Values("autzen_trim.las", "laz/terrascan_fmt8.laz", "lion.ply",
                                         "dragon.ply", "indoor.ply"),
                         test::FileParamName{});

TEST(ExternalSortAdversarial, EqualCodesAcrossRunsKeepTheirInputOrder) {
    test::TempDir dir;
    test::TempDir scratch;
    const std::string path = writeAdversarialCloud(dir, 300'000);
    const SortOptions spilling = spillingOptions(scratch);
    std::size_t runs = 0;
    {
        auto reader = openPointCloud(path);
        IncrementalMortonSorter sorter(reader->info(), spilling);
        ASSERT_TRUE(sorter.spills());
        reader->read([&](const PointBatch& batch) { sorter.add(batch); });
        runs = sorter.runCount();
        // The runs are open, and have no names: a killed process leaves none behind.
        EXPECT_GE(test::openFilesIn(0, scratch.path()).size(), runs);
        EXPECT_EQ(entriesIn(scratch.path()), 0u) << "a run has a name";
    }
    EXPECT_GT(runs, 3u);
    EXPECT_EQ(test::openFilesIn(0, scratch.path()).size(), 0u) << "an abandoned sort left its runs";
    const Sorted external = sortFile(path, spilling);
    const Sorted inMemory = sortFile(path, SortOptions{});
    expectSamePoints(external.points, inMemory.points);
    // Within one code, colours (input indices, 24 bits) ascend: the order is stable.
    const auto inputIndex = [&](std::size_t i) {
        const glm::u8vec3 c = external.points.colors[i];
        return std::uint32_t{c.r} | std::uint32_t{c.g} << 8 | std::uint32_t{c.b} << 16;
    };
    std::size_t unstable = 0;
    for (std::size_t i = 1; i < external.points.size(); ++i) {
        const glm::vec3 a = external.points.positions[i - 1];
        const glm::vec3 b = external.points.positions[i];
        if (morton::encodeUnit(a.x, a.y, a.z) == morton::encodeUnit(b.x, b.y, b.z) &&
            inputIndex(i - 1) >= inputIndex(i)) {
            ++unstable;
        }
    }
    EXPECT_EQ(unstable, 0u);
}

TEST(ExternalSortAdversarial, BatchesWithoutTheCloudAreTheSameStream) {
    test::TempDir dir;
    test::TempDir scratch;
    const std::string path = writeAdversarialCloud(dir, 200'000);
    const SortOptions spilling = spillingOptions(scratch);
    auto reader = openPointCloud(path);
    IncrementalMortonSorter sorter(reader->info(), spilling);
    reader->read([&](const PointBatch& batch) { sorter.add(batch); });
    PointBatch streamed;
    streamed.attributes = reader->info().attributes;
    sorter.emitSortedBatches([&](const PointBatch& sorted) {
        EXPECT_LE(sorted.size(), spilling.batchPoints);
        streamed.append(sorted);
    });
    EXPECT_EQ(sorter.cloud()->sortedEnd(), 0u) << "the batches must not fill the cloud";
    expectSamePoints(streamed, sortFile(path, SortOptions{}).points);
}

PointBatch slice(const PointBatch& from, std::size_t first, std::size_t last) {
    PointBatch part;
    part.attributes = from.attributes;
    const auto copy = [&](const auto& source, auto& target) {
        if (!source.empty()) {
            target.assign(source.begin() + first, source.begin() + last);
        }
    };
    copy(from.positions, part.positions);
    copy(from.normals, part.normals);
    copy(from.colors, part.colors);
    copy(from.intensities, part.intensities);
    return part;
}

// A reader that delivers the first `goodPoints` of a real cloud, then fails as a truncated
// file does; `beforeFailing` runs just before the throw.
class FailingReader : public PointReader {
public:
    FailingReader(const LoadedCloud& cloud, std::size_t goodPoints,
                  std::function<void()> beforeFailing)
        : m_cloud(cloud), m_goodPoints(goodPoints), m_beforeFailing(std::move(beforeFailing)) {
        m_info = cloud.info;
    }
    ReadSummary read(const BatchConsumer& consumer, const ReadOptions&) override {
        constexpr std::size_t kBatch = 10'000;
        for (std::size_t first = 0; first < m_goodPoints; first += kBatch) {
            PointBatch batch = slice(m_cloud.points, first, std::min(m_goodPoints, first + kBatch));
            consumer(batch);
        }
        m_beforeFailing();
        throw InputError(InputErrorKind::Truncated, m_info.path, InputLocation::byte(1234),
                         "expected more records");
    }

private:
    const LoadedCloud& m_cloud;
    std::size_t m_goodPoints;
    std::function<void()> m_beforeFailing;
};

TEST(ExternalSortCleanup, AReaderFailureMidwayRemovesTheRuns) {
    test::TempDir dir;
    test::TempDir scratch;
    const LoadedCloud cloud = loadPointCloud(writeAdversarialCloud(dir, 200'000));
    SortOptions spilling = spillingOptions(scratch);
    // Packed: the cloud stays in memory, so every file open in the scratch folder is a run.
    spilling.storage = PointStorage::Packed;
    const IncrementalMortonSorter* sorter = nullptr;
    std::size_t runsWhenFailing = 0;
    std::size_t filesWhenFailing = 0;
    FailingReader reader(cloud, 150'000, [&] {
        runsWhenFailing = sorter->runCount();
        filesWhenFailing = test::openFilesIn(0, scratch.path()).size();
    });
    EXPECT_THROW(sortPointCloud(
                     reader, spilling, [](const SortedCloud&, std::size_t, std::size_t) {},
                     [&](const IncrementalMortonSorter& ready) { sorter = &ready; }),
                 InputError);
    EXPECT_GT(runsWhenFailing, 1u);
    // One file per run written, and one more for a run being written on the spilling thread
    // (the sorter's thread may start another between the two looks).
    EXPECT_GE(filesWhenFailing, runsWhenFailing) << "one file per run";
    EXPECT_LE(filesWhenFailing, runsWhenFailing + 2) << "one file per run";
    EXPECT_EQ(test::openFilesIn(0, scratch.path()).size(), 0u);
    EXPECT_EQ(entriesIn(scratch.path()), 0u);
}

TEST(ExternalSortCleanup, ACancelDuringTheMergeStopsAndRemovesTheRuns) {
    test::TempDir dir;
    test::TempDir scratch;
    const std::string path = writeAdversarialCloud(dir, 200'000);
    std::atomic<bool> cancel{false};
    SortOptions spilling = spillingOptions(scratch);
    spilling.cancel = &cancel;
    auto reader = openPointCloud(path);
    std::size_t ranges = 0;
    const SortSummary summary =
        sortPointCloud(*reader, spilling, [&](const SortedCloud&, std::size_t, std::size_t) {
            ++ranges;
            cancel.store(true);
        });
    EXPECT_TRUE(summary.cancelled);
    EXPECT_EQ(ranges, 1u);
    EXPECT_EQ(entriesIn(scratch.path()), 0u);
}

// A file size limit makes the runs' writes fail the way a full disk does (EFBIG instead of
// ENOSPC): the error names the folder and the bytes the runs need, and nothing is left.
TEST(ExternalSortCleanup, AFullDiskIsAClearErrorAndLeavesNothing) {
    test::TempDir dir;
    test::TempDir scratch;
    const std::string path = writeAdversarialCloud(dir, 300'000);
    SortOptions spilling = spillingOptions(scratch);
    // Packed: the sorted cloud stays in memory, so the runs are the first to hit the limit
    // (the file-backed cloud's own reservation is the next test).
    spilling.storage = PointStorage::Packed;
    auto reader = openPointCloud(path);
    const std::uint64_t needed =
        reader->info().pointCount * PointRecordLayout::of(reader->info().attributes).bytes;
    const std::string message = outputErrorUnderFileSizeLimit(256 * 1024, [&] { // < a run
        sortPointCloud(*reader, spilling, [](const SortedCloud&, std::size_t, std::size_t) {});
    });
    ASSERT_FALSE(message.empty()) << "the sort ignored a failed write";
    EXPECT_EQ(message.rfind(scratch.path().string() + ": cannot write the sorted run ", 0), 0u)
        << message;
    EXPECT_NE(
        message.find("need " + formatByteSize(needed) + " (" + std::to_string(needed) + " bytes)"),
        std::string::npos)
        << message;
    EXPECT_NE(message.find("--temp-dir"), std::string::npos) << message;
    EXPECT_EQ(entriesIn(scratch.path()), 0u);
}

// An exact cloud beyond the budget lives in a scratch file whose space is reserved up front:
// no room there is an error naming the folder and the bytes before a point is read, and
// nothing is left behind.
TEST(ExternalSortCleanup, NoRoomForTheFileBackedCloudIsAClearErrorUpFront) {
    test::TempDir dir;
    test::TempDir scratch;
    const std::string path = writeAdversarialCloud(dir, 300'000);
    const SortOptions spilling = spillingOptions(scratch);
    auto reader = openPointCloud(path);
    // Less than the cloud's 300,000 x 15 bytes.
    const std::string message = outputErrorUnderFileSizeLimit(1024 * 1024, [&] {
        IncrementalMortonSorter sorter(reader->info(), spilling);
    });
    ASSERT_FALSE(message.empty()) << "the sorter did not reserve the cloud's space";
    EXPECT_EQ(message.rfind(scratch.path().string() + ": cannot keep ", 0), 0u) << message;
    EXPECT_NE(message.find("sorted points beyond the memory budget"), std::string::npos) << message;
    EXPECT_NE(message.find("--temp-dir"), std::string::npos) << message;
    EXPECT_EQ(entriesIn(scratch.path()), 0u);
}

TEST(ExternalSortCleanup, AMissingScratchFolderIsAClearError) {
    OMICRON_REQUIRE_SHARED_FILE(path, "lion.ply");
    SortOptions spilling;
    spilling.memoryBudgetBytes = kMinMemoryBudget;
    spilling.tempDir = "/nonexistent/omicron-scratch";
    auto reader = openPointCloud(path);
    try {
        IncrementalMortonSorter sorter(reader->info(), spilling);
        FAIL() << "a sort spilled into a folder that does not exist";
    } catch (const OutputError& error) {
        EXPECT_EQ(std::string(error.what())
                      .rfind("/nonexistent/omicron-scratch: cannot make scratch files for "
                             "the sorted runs there",
                             0),
                  0u)
            << error.what();
    }
}

TEST(MemoryBudget, SizesParseWithBinarySuffixes) {
    EXPECT_EQ(parseByteSize("512M"), 512 * kMiB);
    EXPECT_EQ(parseByteSize("4G"), 4 * kGiB);
    EXPECT_EQ(parseByteSize("1.5GiB"), 3 * kGiB / 2);
    EXPECT_EQ(parseByteSize("300000000"), 300000000u);
    EXPECT_EQ(parseByteSize("64kb"), 64u * 1024);
    EXPECT_EQ(parseByteSize("2T"), 2048 * kGiB);
    for (const char* bad : {"", "G", "-1G", "4X", "1e30G", "four"}) {
        EXPECT_FALSE(parseByteSize(bad).has_value()) << bad;
    }
    EXPECT_EQ(formatByteSize(512 * kMiB), "512 MiB");
    EXPECT_EQ(formatByteSize(3 * kGiB / 2), "1.5 GiB");
    EXPECT_GE(defaultMemoryBudget(), kMinMemoryBudget);
}

} // namespace
} // namespace omicron
