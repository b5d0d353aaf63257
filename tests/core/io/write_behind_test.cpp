// WriteBehind: each window's write-back starts as soon as the window is complete (the first
// one included), a window leaves the page cache only once the writer is the lag past it, and
// a file written through AtomicFileWriter on a disk really leaves it.
#include "io/atomic_file_writer.hpp"
#include "io/write_behind.hpp"
#include "test_files.hpp"

#include <cstdint>
#include <fcntl.h>
#include <filesystem>
#include <gtest/gtest.h>
#include <linux/magic.h>
#include <sys/mman.h>
#include <sys/vfs.h>
#include <unistd.h>
#include <vector>

namespace omicron {
namespace {

constexpr std::uint64_t kWindow = WriteBehind::kWindowBytes;
constexpr std::uint64_t kLag = WriteBehind::kLagBytes;

// What WriteBehind asked of the file, checked as it goes: write-backs start back to back from
// the region's start, drops follow them back to back, and no window is dropped before its
// write-back started.
struct RecordingFile {
    explicit RecordingFile(std::uint64_t start) : startedEnd(start), droppedEnd(start) {}
    void startWriteBack(std::uint64_t offset, std::uint64_t count) {
        EXPECT_EQ(offset, startedEnd) << "write-backs are not back to back";
        startedEnd = offset + count;
        ++starts;
    }
    void dropFromCache(std::uint64_t offset, std::uint64_t count) {
        EXPECT_EQ(offset, droppedEnd) << "drops are not back to back";
        EXPECT_LE(offset + count, startedEnd) << "dropped before its write-back started";
        droppedEnd = offset + count;
    }
    std::uint64_t startedEnd;
    std::uint64_t droppedEnd;
    int starts = 0;
};

TEST(WriteBehind, EachWindowStartsAsSoonAsCompleteAndLeavesTheCacheTheLagBehind) {
    const std::uint64_t start = 1000; // a level's region starts anywhere in the file
    const std::uint64_t end = start + 11 * kWindow + 12345;
    RecordingFile file(start);
    WriteBehind behind(start);
    for (std::uint64_t written = start; written < end;) {
        written = std::min(end, written + 3'000'017); // blocks that straddle the windows
        behind.advance(file, written);
        const std::uint64_t complete = start + (written - start) / kWindow * kWindow;
        ASSERT_EQ(file.startedEnd, complete) << "at " << written;
        // Cached behind the writer: the lag (a whole number of windows), no more, no less.
        const std::uint64_t lagStart =
            file.startedEnd - start > kLag ? file.startedEnd - kLag : start;
        EXPECT_EQ(file.droppedEnd, lagStart) << "at " << written;
    }
    EXPECT_EQ(file.starts, 11);
    behind.finish(file, end);
    EXPECT_EQ(file.startedEnd, end) << "the last, partial window's write-back was not started";
    EXPECT_EQ(file.starts, 12);
    behind.finish(file, end);
    EXPECT_EQ(file.starts, 12) << "finish started an empty write-back";
}

TEST(WriteBehind, ARegionShorterThanAWindowIsStartedOnlyAtItsEnd) {
    RecordingFile file(0);
    WriteBehind behind;
    behind.advance(file, kWindow - 1);
    EXPECT_EQ(file.starts, 0);
    behind.finish(file, kWindow - 1);
    EXPECT_EQ(file.startedEnd, kWindow - 1);
    EXPECT_EQ(file.droppedEnd, 0u);
}

// How many of the file's pages in [offset, offset + count) are in the page cache.
std::size_t cachedPages(const std::string& path, std::uint64_t offset, std::uint64_t count) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    EXPECT_GE(fd, 0) << path;
    void* mapped = ::mmap(nullptr, count, PROT_READ, MAP_SHARED, fd, static_cast<off_t>(offset));
    ::close(fd);
    EXPECT_NE(mapped, MAP_FAILED);
    const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    std::vector<unsigned char> resident((count + page - 1) / page);
    EXPECT_EQ(::mincore(mapped, count, resident.data()), 0);
    ::munmap(mapped, count);
    std::size_t cached = 0;
    for (const unsigned char r : resident) {
        cached += r & 1u;
    }
    return cached;
}

TEST(WriteBehind, AFileWrittenOnADiskLeavesThePageCacheBehindTheWriter) {
    test::TempDir dir;
    struct statfs fs {};
    ASSERT_EQ(::statfs(dir.path().c_str(), &fs), 0);
    if (fs.f_type != EXT4_SUPER_MAGIC && fs.f_type != XFS_SUPER_MAGIC &&
        fs.f_type != BTRFS_SUPER_MAGIC) {
        GTEST_SKIP() << dir.path() << " is not on ext4, XFS or Btrfs (a tmpfs keeps its pages)";
    }
    const std::string path = (dir.path() / "big.bin").string();
    const std::uint64_t bytes = kLag + 4 * kWindow;
    {
        AtomicFileWriter file(path);
        const std::vector<char> block(std::size_t{1} << 20, 'w');
        for (std::uint64_t at = 0; at < bytes; at += block.size()) {
            file.write(block.data(), block.size());
        }
        file.commit();
    }
    ASSERT_EQ(std::filesystem::file_size(path), bytes);
    // The windows the lag left behind were written back and dropped while the file was written.
    const std::uint64_t dropped = bytes - kLag - WriteBehind::kWindowBytes;
    EXPECT_EQ(cachedPages(path, 0, dropped), 0u);
}

} // namespace
} // namespace omicron
