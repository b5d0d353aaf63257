// Uniform columns: intensities or a LAS column that hold one value for every point are not
// copied into the sorter's arrival arrays and are stored once in the sorted cloud; a column that
// stops being uniform at any point (first batch, a batch boundary, mid-batch, the last point)
// becomes an ordinary one, and every point keeps its own value either way.
#include "points/morton_batch.hpp"
#include "sort/morton_sorter.hpp"
#include "sort/run_merger.hpp"
#include "sort/run_spiller.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <gtest/gtest.h>
#include <random>
#include <thread>
#include <vector>

namespace omicron {
namespace {

constexpr std::size_t kPoints = 50000;
constexpr std::size_t kFeedBatch = 4096;

// Normal, intensity and a LAS column with GPS time (16 bytes); normal.z is the input index.
struct Input {
    CloudInfo info;
    PointBatch points;
};

// Every intensity is 7 and every LAS record the same pattern, except the point at
// `intensityChangesAt` / `lasChangesAt` and after it (kPoints: never).
Input makeInput(std::size_t intensityChangesAt, std::size_t lasChangesAt) {
    Input input;
    input.info.path = "synthetic";
    input.info.pointCount = kPoints;
    input.info.attributes = AttributeSet(Attribute::Normal) | Attribute::Intensity |
                            Attribute::Las | Attribute::GpsTime;
    input.points.attributes = input.info.attributes;
    const std::size_t lasBytes = input.info.attributes.lasBytes();
    std::mt19937_64 random(42);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (std::size_t i = 0; i < kPoints; ++i) {
        input.points.positions.emplace_back(unit(random), unit(random), unit(random));
        input.points.normals.emplace_back(0.0f, 0.0f, float(i));
        input.points.intensities.push_back(
            i < intensityChangesAt ? 7 : static_cast<std::uint16_t>(random()));
        for (std::size_t b = 0; b < lasBytes; ++b) {
            input.points.las.push_back(i < lasChangesAt ? static_cast<std::uint8_t>(b * 3 + 1)
                                                        : static_cast<std::uint8_t>(random()));
        }
    }
    return input;
}

// Sorts `input` fed in batches of kFeedBatch, with another thread faulting arrival pages in
// ahead (as the reader does), and checks every point's attributes against its input point.
// `budget`: the sort's memory budget (0: the default, in memory).
std::shared_ptr<const SortedCloud> sortAndCheck(const Input& input, std::uint64_t budget = 0) {
    SortOptions options;
    options.chunks = 4;
    options.memoryBudgetBytes = budget;
    IncrementalMortonSorter sorter(input.info, options);
    EXPECT_EQ(sorter.spills(), budget != 0);
    std::atomic<std::size_t> added{0};
    std::atomic<bool> reading{true};
    std::thread populator([&] {
        while (reading.load()) {
            if (!sorter.populateAhead(added.load() + 2 * kFeedBatch)) {
                std::this_thread::yield();
            }
        }
    });
    const std::size_t lasBytes = input.info.attributes.lasBytes();
    for (std::size_t begin = 0; begin < kPoints; begin += kFeedBatch) {
        const std::size_t end = std::min(kPoints, begin + kFeedBatch);
        PointBatch batch;
        batch.attributes = input.points.attributes;
        batch.appendRange(input.points, begin, end);
        sorter.add(batch);
        added = end;
    }
    reading = false;
    populator.join();
    sorter.sortAndEmit([](const SortedCloud&, std::size_t, std::size_t) {});
    const auto sorted = sorter.cloud();
    EXPECT_TRUE(sorted->complete());
    EXPECT_EQ(sorted->sortedEnd(), kPoints);
    std::vector<bool> seen(kPoints, false);
    for (std::size_t i = 0; i < sorted->sortedEnd(); ++i) {
        const auto from = static_cast<std::size_t>(sorted->normals()[i].z);
        EXPECT_FALSE(seen[from]);
        seen[from] = true;
        EXPECT_EQ(sorted->positions()[i], input.points.positions[from]);
        EXPECT_EQ(sorted->intensities()[i], input.points.intensities[from]) << i;
        EXPECT_EQ(
            std::memcmp(sorted->lasRecord(i), input.points.las.data() + from * lasBytes, lasBytes),
            0)
            << i;
    }
    return sorted;
}

// The bytes a cloud of kPoints keeps for a column of `bytes` bytes a point.
constexpr std::size_t columnBytes(std::size_t bytes) {
    return kPoints * bytes;
}

TEST(UniformColumns, OneValueForEveryPointIsStoredOnce) {
    const auto uniform = sortAndCheck(makeInput(kPoints, kPoints));
    EXPECT_TRUE(uniform->uniformIntensities());
    EXPECT_TRUE(uniform->uniformLasColumn());
    EXPECT_EQ(uniform->intensities().stride, 0u);
    EXPECT_EQ(uniform->lasColumn().stride, 0u);

    const auto ordinary = sortAndCheck(makeInput(0, 0));
    EXPECT_FALSE(ordinary->uniformIntensities());
    EXPECT_FALSE(ordinary->uniformLasColumn());
    EXPECT_EQ(ordinary->bytesResident() - uniform->bytesResident(),
              columnBytes(sizeof(std::uint16_t)) + columnBytes(16));
}

TEST(UniformColumns, AColumnThatChangesAnywhereKeepsEveryValue) {
    // The second point, the first point of a later batch, mid-batch, the last point.
    for (const std::size_t at :
         {std::size_t{1}, 3 * kFeedBatch, 5 * kFeedBatch + 17, kPoints - 1}) {
        SCOPED_TRACE(at);
        const auto intensitiesChange = sortAndCheck(makeInput(at, kPoints));
        EXPECT_FALSE(intensitiesChange->uniformIntensities());
        EXPECT_TRUE(intensitiesChange->uniformLasColumn());

        const auto lasChanges = sortAndCheck(makeInput(kPoints, at));
        EXPECT_TRUE(lasChanges->uniformIntensities());
        EXPECT_FALSE(lasChanges->uniformLasColumn());
    }
}

// A sort larger than its budget (runs on disk, merged into a sorted cloud in a scratch file)
// finds them too: the runs keep every column, the merged cloud stores a uniform one once.
TEST(UniformColumns, ASpillingSortStoresThemOnceToo) {
    constexpr std::uint64_t kBudget = 256 * 1024; // far below the in-memory sort
    const auto uniform = sortAndCheck(makeInput(kPoints, kPoints), kBudget);
    EXPECT_TRUE(uniform->fileBacked());
    EXPECT_TRUE(uniform->uniformIntensities());
    EXPECT_TRUE(uniform->uniformLasColumn());

    // Changes in a later run, and mid-batch in the first.
    const auto intensitiesChange = sortAndCheck(makeInput(kPoints - 1, kPoints), kBudget);
    EXPECT_FALSE(intensitiesChange->uniformIntensities());
    EXPECT_TRUE(intensitiesChange->uniformLasColumn());
    const auto lasChanges = sortAndCheck(makeInput(kPoints, 17), kBudget);
    EXPECT_TRUE(lasChanges->uniformIntensities());
    EXPECT_FALSE(lasChanges->uniformLasColumn());
}

// The runs themselves: one spilled while a column is uniform leaves it out (smaller records),
// and the merge gives every point of it the value back, point for point the input's.
TEST(UniformColumns, RunsLeaveOutTheColumnsUniformWhenTheyAreSpilled) {
    const Input input = makeInput(kPoints, kPoints / 2); // the LAS column changes half-way
    const AttributeSet attributes = input.info.attributes;
    const std::size_t lasBytes = attributes.lasBytes();
    const std::size_t fullBytes = PointRecordLayout::of(attributes).bytes;
    std::vector<morton::Code> codes(kPoints);
    morton::encodeUnitBatch(input.points.positions, codes);
    std::vector<SortedRun> runs;
    {
        RunSpiller spiller("", attributes, 10000, kPoints);
        for (std::size_t begin = 0; begin < kPoints; begin += kFeedBatch) {
            const std::size_t end = std::min(kPoints, begin + kFeedBatch);
            PointBatch batch;
            batch.attributes = attributes;
            batch.appendRange(input.points, begin, end);
            spiller.add(batch, std::span(codes).subspan(begin, end - begin),
                        {true, end <= kPoints / 2});
        }
        spiller.finish();
        ASSERT_EQ(spiller.runs().size(), 5u);
        for (std::size_t r = 0; r < 5; ++r) {
            SCOPED_TRACE(r);
            const SortedRun& run = spiller.runs()[r];
            // Runs 0 and 1 were spilled before the LAS column changed (point 25,000).
            const std::size_t expected = fullBytes - 2 - (r < 2 ? lasBytes : 0);
            EXPECT_EQ(run.layout.bytes, expected);
            EXPECT_EQ(run.file->size(), run.points * expected);
        }

        RunMerger merger(spiller.runs(), 1 << 20,
                         LeftOutColumns{7, input.points.las.data()}); // point 0's LAS record
        PointBatch merged;
        merged.attributes = attributes;
        ASSERT_EQ(merger.next(merged, kPoints + 1), kPoints);
        for (std::size_t i = 0; i < kPoints; ++i) {
            const auto from = static_cast<std::size_t>(merged.normals[i].z);
            ASSERT_EQ(merged.positions[i], input.points.positions[from]) << i;
            ASSERT_EQ(merged.intensities[i], 7) << i;
            ASSERT_EQ(std::memcmp(merged.las.data() + i * lasBytes,
                                  input.points.las.data() + from * lasBytes, lasBytes),
                      0)
                << i;
        }
    }
}

} // namespace
} // namespace omicron
