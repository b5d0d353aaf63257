// scanRecordsInParallel reads every record exactly once, at the right offset, on oneTBB's
// threads; its in-order callback sees the blocks in file order, can stop the scan, and a file
// shorter than the array is a Truncated error naming the first missing record.
#include "io/input_error.hpp"
#include "io/parallel_record_scan.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <gtest/gtest.h>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace omicron {
namespace {

constexpr std::uint64_t kHeaderBytes = 37;  // records start at an odd offset
constexpr std::uint64_t kRecordBytes = 12;  // a u64 index and a u32 check value
constexpr std::size_t kBlockBytes = 4096;   // 341 records a block
constexpr std::uint64_t kRecords = 100'003; // 294 blocks, the last one short

std::uint32_t checkValue(std::uint64_t index) {
    return static_cast<std::uint32_t>(index * 2654435761u);
}

// A header of junk, then kRecords records, each holding its own index.
std::string writeRecords(const test::TempDir& dir, std::uint64_t records) {
    std::vector<std::uint8_t> bytes(kHeaderBytes, 0xAB);
    bytes.resize(kHeaderBytes + records * kRecordBytes);
    for (std::uint64_t i = 0; i < records; ++i) {
        const std::uint32_t check = checkValue(i);
        std::memcpy(bytes.data() + kHeaderBytes + i * kRecordBytes, &i, sizeof i);
        std::memcpy(bytes.data() + kHeaderBytes + i * kRecordBytes + 8, &check, sizeof check);
    }
    const std::string path = dir.file("records.bin");
    test::writeBytes(path, bytes);
    return path;
}

RecordArray array() {
    return {kHeaderBytes, kRecordBytes, kRecords};
}

TEST(ParallelRecordScan, ReadsEveryRecordOnceAndReportsTheBlocksInFileOrder) {
    test::TempDir dir;
    const FileStream stream(writeRecords(dir, kRecords));
    const std::uint64_t blocks = recordBlockCount(array(), kBlockBytes);
    ASSERT_EQ(blocks, (kRecords + 340) / 341);
    std::vector<std::atomic<int>> seen(kRecords);
    std::atomic<std::uint64_t> wrong{0};
    std::mutex threadsLock;
    std::set<std::thread::id> threads;
    std::vector<std::uint64_t> doneBlocks;
    std::vector<std::uint64_t> doneEnds;
    const bool finished = scanRecordsInParallel(
        stream, array(), kBlockBytes, 16,
        [&](const std::uint8_t* records, std::size_t count, std::uint64_t firstIndex,
            std::uint64_t block) {
            if (block != firstIndex / 341 || firstIndex % 341 != 0) {
                ++wrong;
            }
            for (std::size_t r = 0; r < count; ++r) {
                std::uint64_t index;
                std::uint32_t check;
                std::memcpy(&index, records + r * kRecordBytes, sizeof index);
                std::memcpy(&check, records + r * kRecordBytes + 8, sizeof check);
                if (index != firstIndex + r || check != checkValue(index) || index >= kRecords) {
                    ++wrong;
                    continue;
                }
                seen[index].fetch_add(1);
            }
            std::lock_guard lock(threadsLock);
            threads.insert(std::this_thread::get_id());
        },
        [&](std::uint64_t block, std::uint64_t endByte) {
            doneBlocks.push_back(block); // one call at a time: no lock needed
            doneEnds.push_back(endByte);
            return true;
        });
    EXPECT_TRUE(finished);
    EXPECT_EQ(wrong.load(), 0u);
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](const auto& n) { return n.load() == 1; }));
    ASSERT_EQ(doneBlocks.size(), blocks);
    for (std::uint64_t b = 0; b < blocks; ++b) {
        EXPECT_EQ(doneBlocks[b], b);
        EXPECT_EQ(doneEnds[b], kHeaderBytes + std::min(kRecords, (b + 1) * 341) * kRecordBytes);
    }
    EXPECT_EQ(stream.position(), 0u) << "readAt leaves the stream's position alone";
    RecordProperty("threads", static_cast<int>(threads.size()));
}

TEST(ParallelRecordScan, AFalseFromTheInOrderCallbackStopsTheScan) {
    test::TempDir dir;
    const FileStream stream(writeRecords(dir, kRecords));
    std::atomic<std::uint64_t> scannedBlocks{0};
    std::vector<std::uint64_t> doneBlocks;
    const bool finished = scanRecordsInParallel(
        stream, array(), kBlockBytes, 0,
        [&](const std::uint8_t*, std::size_t, std::uint64_t, std::uint64_t) { ++scannedBlocks; },
        [&](std::uint64_t block, std::uint64_t) {
            doneBlocks.push_back(block);
            return block < 5;
        });
    EXPECT_FALSE(finished);
    EXPECT_EQ(doneBlocks, (std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5}))
        << "no block is passed on after the one that stopped the scan";
    EXPECT_LT(scannedBlocks.load(), recordBlockCount(array(), kBlockBytes))
        << "the threads stop taking blocks";
}

TEST(ParallelRecordScan, AShortFileIsTruncatedAtTheFirstMissingRecord) {
    test::TempDir dir;
    const std::uint64_t present = 5000;
    const FileStream stream(writeRecords(dir, present));
    try {
        scanRecordsInParallel(
            stream, array(), kBlockBytes, 0,
            [](const std::uint8_t*, std::size_t, std::uint64_t, std::uint64_t) {},
            [](std::uint64_t, std::uint64_t) { return true; });
        FAIL() << "a file 95,003 records short was scanned without an error";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::Truncated);
        EXPECT_EQ(error.location().unit, InputLocation::Unit::Byte);
        EXPECT_EQ(error.location().value, kHeaderBytes + present * kRecordBytes);
        const std::string message = error.what();
        EXPECT_NE(message.find("expected record 5000 of 100003"), std::string::npos) << message;
        EXPECT_NE(message.find("the file ends at byte " +
                               std::to_string(kHeaderBytes + present * kRecordBytes)),
                  std::string::npos)
            << message;
    }
}

TEST(ParallelRecordScan, AnExceptionFromTheScanReachesTheCaller) {
    test::TempDir dir;
    const FileStream stream(writeRecords(dir, kRecords));
    EXPECT_THROW(scanRecordsInParallel(
                     stream, array(), kBlockBytes, 0,
                     [](const std::uint8_t*, std::size_t, std::uint64_t, std::uint64_t block) {
                         if (block == 7) {
                             throw std::runtime_error("block 7 is bad");
                         }
                     },
                     [](std::uint64_t, std::uint64_t) { return true; }),
                 std::runtime_error);
}

TEST(ParallelRecordScan, AnEmptyArrayScansNothing) {
    test::TempDir dir;
    const FileStream stream(writeRecords(dir, 0));
    int calls = 0;
    EXPECT_TRUE(scanRecordsInParallel(
        stream, {kHeaderBytes, kRecordBytes, 0}, kBlockBytes, 16,
        [&](const std::uint8_t*, std::size_t, std::uint64_t, std::uint64_t) { ++calls; },
        [&](std::uint64_t, std::uint64_t) {
            ++calls;
            return true;
        }));
    EXPECT_EQ(calls, 0);
}

} // namespace
} // namespace omicron
