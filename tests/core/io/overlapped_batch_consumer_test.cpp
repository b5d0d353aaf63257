// The reader's batches consumed on a thread of their own: every batch once, in order, with its
// content and its points' Morton codes; the reader helps while it waits; a consumer's exception
// reaches the reader; giving up part way neither hangs nor consumes what was left waiting.
#include "io/overlapped_batch_consumer.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <gtest/gtest.h>
#include <span>
#include <stdexcept>
#include <thread>
#include <vector>

namespace omicron {
namespace {

// Batch k holds k % 7 + 1 points whose x is the running point index / 4096 (exact in a float,
// inside the unit cube for the tests' point counts) and whose y and z vary with it.
PointBatch batchNumber(std::size_t k, std::size_t& nextPoint) {
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Intensity);
    for (std::size_t i = 0; i < k % 7 + 1; ++i) {
        const auto index = static_cast<float>(nextPoint++);
        batch.positions.emplace_back(index / 4096.0f, 1.0f - index / 8192.0f,
                                     (index * 7.0f - 4096.0f * std::floor(index * 7.0f / 4096.0f)) /
                                         4096.0f);
        batch.intensities.push_back(static_cast<std::uint16_t>(k));
    }
    return batch;
}

// What the worker received: each point's x and intensity, and how many codes were not the
// codes of the points they came with.
struct ConsumedPoints {
    std::vector<float> xs;
    std::vector<std::uint16_t> intensities;
    std::size_t wrongCodes = 0;

    void record(const PointBatch& batch, std::span<const morton::Code> codes) {
        ASSERT_EQ(codes.size(), batch.size());
        for (std::size_t i = 0; i < batch.size(); ++i) {
            const glm::vec3& p = batch.positions[i];
            xs.push_back(p.x);
            intensities.push_back(batch.intensities[i]);
            wrongCodes += codes[i] != morton::encodeUnit(p.x, p.y, p.z) ? 1 : 0;
        }
    }
};

TEST(OverlappedBatchConsumer, ConsumesEveryBatchOnceInOrderWithItsContent) {
    for (const auto delay : {std::chrono::microseconds(0), std::chrono::microseconds(200)}) {
        ConsumedPoints consumed;
        const std::thread::id reader = std::this_thread::get_id();
        bool otherThread = true;
        OverlappedBatchConsumer consumer([&](const PointBatch& batch,
                                             std::span<const morton::Code> codes) {
            otherThread = otherThread && std::this_thread::get_id() != reader;
            consumed.record(batch, codes);
            std::this_thread::sleep_for(delay); // a consumer slower than the reader
        });
        std::size_t nextPoint = 0;
        std::vector<std::uint16_t> expectedBatches;
        for (std::size_t k = 0; k < 200; ++k) {
            PointBatch batch = batchNumber(k, nextPoint);
            expectedBatches.insert(expectedBatches.end(), batch.size(),
                                   static_cast<std::uint16_t>(k));
            consumer.push(batch);
        }
        consumer.finish();
        EXPECT_TRUE(otherThread);
        ASSERT_EQ(consumed.xs.size(), nextPoint);
        for (std::size_t i = 0; i < consumed.xs.size(); ++i) {
            ASSERT_EQ(consumed.xs[i], static_cast<float>(i) / 4096.0f) << "point " << i;
        }
        EXPECT_EQ(consumed.intensities, expectedBatches);
        EXPECT_EQ(consumed.wrongCodes, 0u);
    }
}

// A reader that rewrites one batch in place, as the file readers do: batches of one shape are
// taken by swapping buffers (the reader's batch comes back as another buffer of the same
// sizes), and the worker still sees every point once, in order.
TEST(OverlappedBatchConsumer, BatchesOfOneShapeAreTakenWithoutACopy) {
    ConsumedPoints consumed;
    OverlappedBatchConsumer consumer(
        [&](const PointBatch& batch, std::span<const morton::Code> codes) {
            consumed.record(batch, codes);
        });
    constexpr std::size_t kPoints = 64;
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Intensity);
    batch.positions.resize(kPoints);
    batch.intensities.resize(kPoints);
    std::size_t swapped = 0;
    for (std::size_t k = 0; k < 100; ++k) {
        for (std::size_t i = 0; i < kPoints; ++i) { // written in place, every column
            const auto index = static_cast<float>(k * kPoints + i);
            batch.positions[i] = glm::vec3(index / 8192.0f, 0.5f, 0.25f);
            batch.intensities[i] = static_cast<std::uint16_t>(k);
        }
        const glm::vec3* before = batch.positions.data();
        consumer.push(batch);
        swapped += batch.positions.data() != before ? 1 : 0;
        ASSERT_EQ(batch.positions.size(), kPoints);
        ASSERT_EQ(batch.intensities.size(), kPoints);
        ASSERT_EQ(batch.attributes, AttributeSet(Attribute::Intensity));
    }
    consumer.finish();
    EXPECT_GE(swapped, 98u) << "every batch after the first two is taken, not copied";
    EXPECT_EQ(consumed.wrongCodes, 0u) << "codes of the points the worker got";
    ASSERT_EQ(consumed.xs.size(), 100 * kPoints);
    for (std::size_t i = 0; i < consumed.xs.size(); ++i) {
        ASSERT_EQ(consumed.xs[i], static_cast<float>(i) / 8192.0f) << "point " << i;
        ASSERT_EQ(consumed.intensities[i], i / kPoints) << "point " << i;
    }
}

// While the worker still holds a batch, the reader runs the helper (on its own thread, with the
// points read so far) until the helper has nothing to do; batches still arrive in order.
TEST(OverlappedBatchConsumer, TheReaderHelpsWhileTheWorkerHoldsABatch) {
    const std::thread::id reader = std::this_thread::get_id();
    std::vector<float> xs;
    std::atomic<bool> consuming{false};
    std::size_t helpCalls = 0;
    std::size_t wrongThread = 0;
    std::vector<std::size_t> pointsReadSeen;
    std::size_t stepsLeft = 0; // the helper's work for the current push
    OverlappedBatchConsumer consumer(
        [&](const PointBatch& batch, std::span<const morton::Code>) {
            consuming = true;
            for (const glm::vec3& p : batch.positions) {
                xs.push_back(p.x);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(3));
            consuming = false;
        },
        [&](std::size_t pointsRead) {
            ++helpCalls;
            wrongThread += std::this_thread::get_id() != reader ? 1 : 0;
            pointsReadSeen.push_back(pointsRead);
            if (stepsLeft == 0) {
                return false;
            }
            --stepsLeft;
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            return true;
        });
    std::size_t nextPoint = 0;
    std::vector<std::size_t> pushedTotals;
    for (std::size_t k = 0; k < 40; ++k) {
        stepsLeft = 3;
        PointBatch batch = batchNumber(k, nextPoint);
        consumer.push(batch);
        pushedTotals.push_back(nextPoint);
    }
    consumer.finish();
    EXPECT_FALSE(consuming.load());
    EXPECT_EQ(wrongThread, 0u);
    EXPECT_GT(helpCalls, 0u) << "a worker 3 ms a batch behind never made the reader wait";
    for (const std::size_t seen : pointsReadSeen) {
        EXPECT_TRUE(std::find(pushedTotals.begin(), pushedTotals.end(), seen) != pushedTotals.end())
            << seen << " is not the point count of a push";
    }
    EXPECT_TRUE(std::is_sorted(pointsReadSeen.begin(), pointsReadSeen.end()));
    ASSERT_EQ(xs.size(), nextPoint);
    for (std::size_t i = 0; i < xs.size(); ++i) {
        ASSERT_EQ(xs[i], static_cast<float>(i) / 4096.0f) << "point " << i;
    }
}

TEST(OverlappedBatchConsumer, TheConsumersExceptionReachesTheReader) {
    std::atomic<std::size_t> consumed{0};
    OverlappedBatchConsumer consumer([&](const PointBatch&, std::span<const morton::Code>) {
        if (consumed.fetch_add(1) == 5) {
            throw std::length_error("more points than declared");
        }
    });
    std::size_t nextPoint = 0;
    bool thrown = false;
    try {
        for (std::size_t k = 0; k < 1000; ++k) {
            PointBatch batch = batchNumber(k, nextPoint);
            consumer.push(batch);
        }
        consumer.finish();
    } catch (const std::length_error& error) {
        thrown = true;
        EXPECT_STREQ(error.what(), "more points than declared");
    }
    EXPECT_TRUE(thrown);
    EXPECT_EQ(consumed.load(), 6u) << "batches were consumed after the failure";
}

TEST(OverlappedBatchConsumer, GivingUpPartWayDropsWhatWaitsAndJoins) {
    std::atomic<std::size_t> consumed{0};
    std::size_t pushed = 0;
    {
        OverlappedBatchConsumer consumer([&](const PointBatch&, std::span<const morton::Code>) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            consumed.fetch_add(1);
        });
        std::size_t nextPoint = 0;
        for (std::size_t k = 0; k < 3; ++k) {
            PointBatch batch = batchNumber(k, nextPoint);
            consumer.push(batch);
            ++pushed;
        }
        // The reader threw here: no finish(), the destructor must not hang.
    }
    EXPECT_GE(consumed.load(), 1u);
    EXPECT_LE(consumed.load(), pushed);
}

} // namespace
} // namespace omicron
