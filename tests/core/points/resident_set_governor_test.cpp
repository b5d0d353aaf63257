// The governor over a real file mapping, under a budget the process is always over (its own
// code and libraries alone exceed it): it drops the mapping's pages once they are resident,
// then not again while nothing more is touched (each drop is a TLB shootdown on every core),
// and again once the mapping's pages come back.
#include "memory_budget.hpp"
#include "points/resident_set_governor.hpp"
#include "test_files.hpp"

#include <chrono>
#include <cstdint>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace omicron {
namespace {

constexpr std::size_t kMappingBytes = std::size_t{16} << 20;
constexpr std::uint64_t kLimit = std::uint64_t{4} << 20; // drops are worth 512 KiB of growth

class FileMapping {
public:
    explicit FileMapping(const std::string& path) {
        const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
        EXPECT_GE(fd, 0);
        std::vector<char> bytes(kMappingBytes, 1);
        EXPECT_EQ(::write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
        void* memory = ::mmap(nullptr, kMappingBytes, PROT_READ, MAP_SHARED, fd, 0);
        ::close(fd);
        EXPECT_NE(memory, MAP_FAILED);
        m_bytes = static_cast<const volatile char*>(memory);
    }
    ~FileMapping() { ::munmap(const_cast<char*>(m_bytes), kMappingBytes); }

    // Faults every page in (from the page cache: the file was just written).
    void touch() const {
        long sum = 0;
        for (std::size_t i = 0; i < kMappingBytes; i += 4096) {
            sum += m_bytes[i];
        }
        EXPECT_EQ(sum, static_cast<long>(kMappingBytes / 4096));
    }
    void drop() const { ::madvise(const_cast<char*>(m_bytes), kMappingBytes, MADV_DONTNEED); }

private:
    const volatile char* m_bytes = nullptr;
};

// Looks until a drop is counted (the governor's thread may be the one that drops), up to 2 s.
bool dropsBeyond(ResidentSetGovernor& governor, std::uint64_t drops) {
    for (int i = 0; i < 1000 && governor.drops() <= drops; ++i) {
        governor.checkNow();
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return governor.drops() > drops;
}

TEST(ResidentSetGovernor, DropsAgainOnlyOnceTheMappingsPagesCameBack) {
    test::TempDir dir;
    const FileMapping mapping(dir.file("cloud.bin"));
    ASSERT_GT(processResidentSet().bytes, kLimit) << "the process is under the budget";
    mapping.touch(); // before the governor's first look: a drop amid the touch is followed by
                     // another for the pages touched after it
    ResidentSetGovernor governor(kLimit, [&] { mapping.drop(); });
    ASSERT_TRUE(dropsBeyond(governor, 0)) << "16 MiB of file pages over a 4 MiB budget stayed";
    // A look that raced with the first drop (the thread's and ours) has finished.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));

    // Nothing touched: still over the budget (by the program's own pages), but nothing that a
    // drop would give back. 50 looks of the thread's, and 25 of our own.
    const std::uint64_t drops = governor.drops();
    for (int i = 0; i < 25; ++i) {
        governor.checkNow();
        std::this_thread::sleep_for(std::chrono::milliseconds(4));
    }
    EXPECT_EQ(governor.drops(), drops) << "dropped again with no page of the mapping back";

    mapping.touch();
    EXPECT_TRUE(dropsBeyond(governor, drops)) << "the mapping's pages came back and stayed";
}

} // namespace
} // namespace omicron
