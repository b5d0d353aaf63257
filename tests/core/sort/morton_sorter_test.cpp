// The incremental Morton sorter: sorted permutation of the input, the prefix guarantee of
// every emitted range, identical output for every chunk count and thread count, preview.
#include "io/point_reader.hpp"
#include "sort/morton_sorter.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <gtest/gtest.h>
#include <optional>
#include <random>
#include <tbb/global_control.h>
#include <thread>
#include <tuple>
#include <vector>

namespace omicron {
namespace {

// A cloud already in the unit cube with every attribute, as a reader would deliver it.
struct SyntheticCloud {
    CloudInfo info;
    PointBatch points;
};

// MortonOrdered: random points arriving already in Morton order (as coherent as input gets):
// the sorter gives its input back block by block while it sorts.
enum class Shape { Random, Duplicates, AllIdentical, TwoClusters, MaxFaces, MortonOrdered };

SyntheticCloud makeCloud(Shape shape, std::size_t count, std::uint64_t seed) {
    SyntheticCloud cloud;
    cloud.info.path = "synthetic";
    cloud.info.pointCount = count;
    cloud.info.attributes =
        AttributeSet(Attribute::Color) | Attribute::Normal | Attribute::Intensity;
    cloud.points.attributes = cloud.info.attributes;
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (std::size_t i = 0; i < count; ++i) {
        glm::vec3 p{unit(random), unit(random), unit(random)};
        switch (shape) {
        case Shape::Random:
        case Shape::MortonOrdered: // ordered below
            break;
        case Shape::Duplicates:
            p = glm::vec3(float(i % 97) / 97.0f, 0.5f, float(i % 13) / 13.0f);
            break;
        case Shape::AllIdentical:
            p = glm::vec3(0.25f, 0.75f, 0.5f);
            break;
        case Shape::TwoClusters:
            p = (i % 2 == 0 ? glm::vec3(0.0f) : glm::vec3(0.999f)) + p * 0.001f;
            break;
        case Shape::MaxFaces:
            p = glm::vec3(1.0f, i % 2 == 0 ? 1.0f : p.y, 1.0f);
            break;
        }
        cloud.points.positions.push_back(p);
    }
    if (shape == Shape::MortonOrdered) {
        std::stable_sort(cloud.points.positions.begin(), cloud.points.positions.end(),
                         [](const glm::vec3& a, const glm::vec3& b) {
                             return morton::encodeUnit(a.x, a.y, a.z) <
                                    morton::encodeUnit(b.x, b.y, b.z);
                         });
    }
    for (std::size_t i = 0; i < count; ++i) {
        cloud.points.normals.push_back(glm::vec3(0.0f, 0.0f, float(i)));
        cloud.points.colors.push_back(glm::u8vec3(i & 0xff, (i >> 8) & 0xff, (i >> 16) & 0xff));
        cloud.points.intensities.push_back(static_cast<std::uint16_t>(i));
    }
    return cloud;
}

struct SortRun {
    std::vector<morton::Code> codes;
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals; // normal.z carries the input index: checks the permutation
    std::vector<std::pair<std::size_t, std::size_t>> ranges;
    bool prefixGuaranteeHeld = true;
    bool complete = false;
    std::size_t pagesRecycled = 0;
};

// `populating`: another thread faults the arrival pages in ahead of add() meanwhile
// (populateAhead, as the reader does while it waits for the sorter).
SortRun sortCloud(const SyntheticCloud& cloud, int chunks, std::size_t feedBatch = 10000,
                  std::size_t emitBatch = 5000, std::optional<bool> recyclePages = std::nullopt,
                  bool populating = false, std::size_t recyclePageBytes = 0) {
    SortOptions options;
    options.chunks = chunks;
    options.batchPoints = emitBatch;
    options.recyclePages = recyclePages;
    options.recyclePageBytes = recyclePageBytes;
    IncrementalMortonSorter sorter(cloud.info, options);
    std::atomic<std::size_t> added{0};
    std::atomic<bool> reading{true};
    std::thread populator;
    if (populating) {
        populator = std::thread([&] {
            while (reading.load()) {
                if (!sorter.populateAhead(added.load() + 2 * feedBatch)) {
                    std::this_thread::yield();
                }
            }
        });
    }
    const auto stopPopulating = [&] {
        reading = false;
        if (populator.joinable()) {
            populator.join();
        }
    };
    for (std::size_t begin = 0; begin < cloud.points.size(); begin += feedBatch) {
        const std::size_t end = std::min(cloud.points.size(), begin + feedBatch);
        PointBatch batch;
        batch.attributes = cloud.points.attributes;
        batch.positions.assign(cloud.points.positions.begin() + begin,
                               cloud.points.positions.begin() + end);
        batch.normals.assign(cloud.points.normals.begin() + begin,
                             cloud.points.normals.begin() + end);
        batch.colors.assign(cloud.points.colors.begin() + begin, cloud.points.colors.begin() + end);
        batch.intensities.assign(cloud.points.intensities.begin() + begin,
                                 cloud.points.intensities.begin() + end);
        sorter.add(batch);
        added = end;
    }
    stopPopulating();
    SortRun run;
    morton::Code maxEmitted = 0;
    sorter.sortAndEmit([&](const SortedCloud& sorted, std::size_t begin, std::size_t end) {
        EXPECT_LE(end, sorted.sortedEnd()) << "a range was handed out before it was published";
        EXPECT_LE(end - begin, emitBatch);
        EXPECT_EQ(begin, run.ranges.empty() ? 0 : run.ranges.back().second);
        run.ranges.emplace_back(begin, end);
        for (std::size_t i = begin; i < end; ++i) {
            if (sorted.code(i) < maxEmitted) {
                run.prefixGuaranteeHeld = false;
            }
        }
        maxEmitted = std::max(maxEmitted, sorted.code(end - 1));
    });
    const auto sorted = sorter.cloud();
    run.complete = sorted->complete();
    run.pagesRecycled = sorter.pagesRecycled();
    const std::size_t count = sorted->sortedEnd();
    run.codes.clear();
    for (std::size_t i = 0; i < count; ++i) {
        run.codes.push_back(sorted->code(i));
    }
    run.positions.assign(sorted->positions().begin(), sorted->positions().begin() + count);
    run.normals.assign(sorted->normals().begin(), sorted->normals().begin() + count);
    // Attributes travel with their point.
    for (std::size_t i = 0; i < count; ++i) {
        const auto from = static_cast<std::size_t>(sorted->normals()[i].z);
        EXPECT_EQ(sorted->colors()[i], cloud.points.colors[from]);
        EXPECT_EQ(sorted->intensities()[i], cloud.points.intensities[from]);
        EXPECT_EQ(sorted->positions()[i], cloud.points.positions[from]);
    }
    return run;
}

void expectSortedPermutation(const SyntheticCloud& cloud, const SortRun& run) {
    ASSERT_TRUE(run.complete);
    ASSERT_EQ(run.codes.size(), cloud.points.size());
    EXPECT_TRUE(run.prefixGuaranteeHeld);
    EXPECT_TRUE(std::is_sorted(run.codes.begin(), run.codes.end()));
    std::vector<bool> seen(cloud.points.size(), false);
    for (std::size_t i = 0; i < run.normals.size(); ++i) {
        const auto from = static_cast<std::size_t>(run.normals[i].z);
        ASSERT_FALSE(seen[from]) << "input point " << from << " emitted twice";
        seen[from] = true;
        const glm::vec3& p = cloud.points.positions[from];
        ASSERT_EQ(run.codes[i], morton::encodeUnit(p.x, p.y, p.z));
        if (i > 0 && run.codes[i] == run.codes[i - 1]) {
            // Stable: equal codes keep input order.
            ASSERT_LT(run.normals[i - 1].z, run.normals[i].z);
        }
    }
}

class MortonSorterShapes : public ::testing::TestWithParam<std::tuple<Shape, int>> {};

TEST_P(MortonSorterShapes, SortedStablePermutationWithPrefixGuarantee) {
    const auto [shape, chunks] = GetParam();
    const SyntheticCloud cloud = makeCloud(shape, 60000, 3);
    expectSortedPermutation(cloud, sortCloud(cloud, chunks));
}

INSTANTIATE_TEST_SUITE_P(Shapes, MortonSorterShapes,
                         ::testing::Combine(::testing::Values(Shape::Random, Shape::Duplicates,
                                                              Shape::AllIdentical,
                                                              Shape::TwoClusters, Shape::MaxFaces),
                                            ::testing::Values(1, 3, 32, 256)));

// Blocks of 65536 input points are given back once the last chunk that gathers from them is
// sorted: with input in Morton order that happens chunk after chunk, and every attribute must
// still come from its point (a block given back too early reads as zeros).
TEST(MortonSorter, InputGivenBackWhileSortingKeepsEveryAttribute) {
    const SyntheticCloud cloud = makeCloud(Shape::MortonOrdered, 330000, 5);
    for (int chunks : {2, 7, 32, 256}) {
        SCOPED_TRACE(chunks);
        expectSortedPermutation(cloud, sortCloud(cloud, chunks, 65536, 65536));
    }
}

// Given-back input pages are moved into the sorted cloud instead of faulting fresh ones (4 KiB
// pages block by block; 2 MiB pages, on huge pages, once every block they hold is done): the
// moved pages hold stale input until the gather overwrites them, so a page moved under a range
// already written, or one not written over, or given back while a later chunk still gathers
// from it, shows here.
class MortonSorterRecycling : public ::testing::TestWithParam<std::size_t> {};

TEST_P(MortonSorterRecycling, InputPagesMovedIntoTheSortedCloudKeepEveryAttribute) {
    const std::size_t pageBytes = GetParam();
    // A few dozen pages of each column either way.
    const std::size_t points = pageBytes == 4096 ? 330000 : 700000;
    for (const Shape shape : {Shape::MortonOrdered, Shape::Random, Shape::TwoClusters}) {
        SCOPED_TRACE(static_cast<int>(shape));
        const SyntheticCloud cloud = makeCloud(shape, points, 11);
        for (int chunks : {1, 7, 32}) {
            SCOPED_TRACE(chunks);
            const SortRun moved = sortCloud(cloud, chunks, 65536, 65536, true, false, pageBytes);
            const SortRun faulted = sortCloud(cloud, chunks, 65536, 65536, false);
            expectSortedPermutation(cloud, moved);
            EXPECT_EQ(moved.normals, faulted.normals);
            EXPECT_EQ(faulted.pagesRecycled, 0u);
            if (shape == Shape::MortonOrdered && chunks > 1) {
                EXPECT_GT(moved.pagesRecycled, 0u) << "input given back chunk after chunk";
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(PageSizes, MortonSorterRecycling,
                         ::testing::Values(std::size_t{4096}, std::size_t{2} << 20));

// The reader faults arrival pages in while the sorter adds: the sort is the same point for
// point, whichever thread touched a page first, and pages moved into the sorted cloud later
// still carry their own points.
TEST(MortonSorter, ArrivalPagesPopulatedFromAnotherThreadKeepEveryAttribute) {
    for (const Shape shape : {Shape::Random, Shape::MortonOrdered}) {
        SCOPED_TRACE(static_cast<int>(shape));
        const SyntheticCloud cloud = makeCloud(shape, 330000, 13);
        const SortRun reference = sortCloud(cloud, 32);
        for (const bool recycle : {true, false}) {
            const SortRun run = sortCloud(cloud, 32, 7000, 5000, recycle, true);
            expectSortedPermutation(cloud, run);
            EXPECT_EQ(run.codes, reference.codes);
            EXPECT_EQ(run.normals, reference.normals);
        }
    }
}

// populateAhead claims each point's pages once, a step at a time, never past the limit or the
// declared count; a spilling sort has nothing to populate.
TEST(MortonSorter, PopulateAheadClaimsUpToTheLimitAndTheDeclaredCount) {
    const SyntheticCloud cloud = makeCloud(Shape::Random, 50000, 17);
    IncrementalMortonSorter sorter(cloud.info, {});
    EXPECT_FALSE(sorter.populateAhead(0));
    EXPECT_TRUE(sorter.populateAhead(10));
    EXPECT_FALSE(sorter.populateAhead(10)) << "claimed twice";
    std::size_t steps = 0;
    while (sorter.populateAhead(1'000'000)) {
        ++steps;
        ASSERT_LT(steps, 100u) << "claims past the declared 50000 points";
    }
    EXPECT_EQ(steps, (50000u - 10u + 16383u) / 16384u);
    sorter.add(cloud.points); // pages claimed ahead: add() copies into them
    std::vector<morton::Code> codes;
    sorter.sortAndEmit([&](const SortedCloud& sorted, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            codes.push_back(sorted.code(i));
        }
    });
    ASSERT_EQ(codes.size(), 50000u);
    EXPECT_TRUE(std::is_sorted(codes.begin(), codes.end()));

    SortOptions spilling;
    spilling.memoryBudgetBytes = 1 << 20;
    IncrementalMortonSorter spiller(cloud.info, spilling);
    ASSERT_TRUE(spiller.spills());
    EXPECT_FALSE(spiller.populateAhead(1000));
}

TEST(MortonSorter, IdenticalForEveryChunkCountAndThreadCount) {
    const SyntheticCloud cloud = makeCloud(Shape::Random, 120000, 9);
    SortRun reference;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        reference = sortCloud(cloud, 1);
    }
    expectSortedPermutation(cloud, reference);
    for (int threads : {1, 2, 4}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        for (int chunks : {1, 2, 4, 8, 16, 32, 64, 256}) {
            const SortRun run = sortCloud(cloud, chunks);
            ASSERT_EQ(run.codes, reference.codes) << threads << " threads, " << chunks << " chunks";
            ASSERT_EQ(run.normals, reference.normals) << threads << " threads, " << chunks;
        }
    }
}

TEST(MortonSorter, ChunkedModeEmitsBeforeTheLastChunkIsSorted) {
    const SyntheticCloud cloud = makeCloud(Shape::Random, 200000, 4);
    SortOptions options;
    options.chunks = 16;
    IncrementalMortonSorter sorter(cloud.info, options);
    sorter.add(cloud.points);
    std::size_t publishedAtFirstRange = 0;
    const int chunks = sorter.sortAndEmit([&](const SortedCloud& sorted, std::size_t, std::size_t) {
        if (publishedAtFirstRange == 0) {
            publishedAtFirstRange = sorted.sortedEnd();
        }
    });
    EXPECT_EQ(chunks, 16);
    EXPECT_GT(publishedAtFirstRange, 0u);
    // At most two chunks (the one handed out and the one sorted meanwhile) were published.
    EXPECT_LE(publishedAtFirstRange, 2 * cloud.points.size() / 16 + 4096);
}

TEST(MortonSorter, CancellationStopsBetweenRangesAndLeavesCloudIncomplete) {
    const SyntheticCloud cloud = makeCloud(Shape::Random, 100000, 5);
    std::atomic<bool> cancel{false};
    SortOptions options;
    options.chunks = 32;
    options.batchPoints = 1000;
    options.cancel = &cancel;
    IncrementalMortonSorter sorter(cloud.info, options);
    sorter.add(cloud.points);
    std::size_t ranges = 0;
    sorter.sortAndEmit([&](const SortedCloud&, std::size_t, std::size_t) {
        ++ranges;
        cancel = true;
    });
    EXPECT_EQ(ranges, 1u);
    EXPECT_FALSE(sorter.cloud()->complete());
}

TEST(MortonSorter, PreviewIsABoundedSubsetAvailableWhileReading) {
    const SyntheticCloud cloud = makeCloud(Shape::Random, 50000, 6);
    SortOptions options;
    options.previewPoints = 1000;
    IncrementalMortonSorter sorter(cloud.info, options);
    PointBatch first;
    first.attributes = cloud.points.attributes;
    first.positions.assign(cloud.points.positions.begin(), cloud.points.positions.begin() + 400);
    first.normals.assign(cloud.points.normals.begin(), cloud.points.normals.begin() + 400);
    first.colors.assign(cloud.points.colors.begin(), cloud.points.colors.begin() + 400);
    first.intensities.assign(cloud.points.intensities.begin(),
                             cloud.points.intensities.begin() + 400);
    sorter.add(first);
    PreviewSample preview = sorter.preview();
    EXPECT_EQ(preview.positions.size(), 400u);
    EXPECT_EQ(preview.colors.size(), 400u);
    EXPECT_EQ(preview.pointsSeen, 400u);

    PointBatch rest;
    rest.attributes = cloud.points.attributes;
    rest.positions.assign(cloud.points.positions.begin() + 400, cloud.points.positions.end());
    rest.normals.assign(cloud.points.normals.begin() + 400, cloud.points.normals.end());
    rest.colors.assign(cloud.points.colors.begin() + 400, cloud.points.colors.end());
    rest.intensities.assign(cloud.points.intensities.begin() + 400, cloud.points.intensities.end());
    sorter.add(rest);
    preview = sorter.preview();
    EXPECT_EQ(preview.positions.size(), 1000u);
    EXPECT_EQ(preview.pointsSeen, 50000u);
    // Every preview point is an input point with its own colour, and the sample reaches
    // beyond the first batch (it is a sample of everything seen, not a prefix).
    std::size_t fromLaterBatches = 0;
    for (std::size_t i = 0; i < preview.positions.size(); ++i) {
        const auto it = std::find(cloud.points.positions.begin(), cloud.points.positions.end(),
                                  preview.positions[i]);
        ASSERT_NE(it, cloud.points.positions.end());
        const auto index = static_cast<std::size_t>(it - cloud.points.positions.begin());
        EXPECT_EQ(preview.colors[i], cloud.points.colors[index]);
        fromLaterBatches += index >= 400 ? 1 : 0;
    }
    EXPECT_GT(fromLaterBatches, 900u);
}

TEST(MortonSorter, RejectsMorePointsThanDeclared) {
    SyntheticCloud cloud = makeCloud(Shape::Random, 100, 7);
    cloud.info.pointCount = 50;
    IncrementalMortonSorter sorter(cloud.info, {});
    EXPECT_THROW(sorter.add(cloud.points), std::length_error);
}

// Real scans through the real readers: pipeline 1 end to end.
class MortonSorterSharedData : public ::testing::TestWithParam<const char*> {};

TEST_P(MortonSorterSharedData, SortsEveryPointOfTheFile) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    auto reader = openPointCloud(path);
    const CloudInfo info = reader->info();
    const LoadedCloud original = loadPointCloud(path);
    std::shared_ptr<const SortedCloud> sorted;
    morton::Code maxEmitted = 0;
    bool prefixGuaranteeHeld = true;
    const SortSummary summary = sortPointCloud(
        *reader, SortOptions{},
        [&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
            prefixGuaranteeHeld = prefixGuaranteeHeld && cloud.code(begin) >= maxEmitted;
            maxEmitted = cloud.code(end - 1);
        },
        [&](const IncrementalMortonSorter& sorter) { sorted = sorter.cloud(); });
    ASSERT_TRUE(sorted);
    EXPECT_TRUE(prefixGuaranteeHeld);
    EXPECT_TRUE(sorted->complete());
    EXPECT_EQ(summary.points, original.points.size());
    EXPECT_EQ(sorted->sortedEnd(), original.points.size());
    std::vector<morton::Code> codes;
    for (std::size_t i = 0; i < sorted->sortedEnd(); ++i) {
        codes.push_back(sorted->code(i));
    }
    EXPECT_TRUE(std::is_sorted(codes.begin(), codes.end()));
    // Same multiset of positions: compare both sides sorted by their bit patterns.
    const auto key = [](const glm::vec3& p) {
        std::array<std::uint32_t, 3> bits;
        std::memcpy(bits.data(), &p, sizeof bits);
        return bits;
    };
    std::vector<std::array<std::uint32_t, 3>> in, out;
    for (const auto& p : original.points.positions) {
        in.push_back(key(p));
    }
    for (std::size_t i = 0; i < sorted->sortedEnd(); ++i) {
        out.push_back(key(sorted->positions()[i]));
    }
    std::sort(in.begin(), in.end());
    std::sort(out.begin(), out.end());
    EXPECT_TRUE(in == out);
    EXPECT_EQ(info.cube, sorted->cube());
}

INSTANTIATE_TEST_SUITE_P(Files, MortonSorterSharedData,
                         ::testing::Values("bunny.ply", "autzen_trim.ply", "autzen_trim.las",
                                           "lion.ply", "sorvilier.ply", "indoor.ply", "dragon.ply",
                                           "autzen_south.ply"),
                         test::FileParamName());

} // namespace
} // namespace omicron
