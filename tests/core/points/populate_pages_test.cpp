// populatePages: the pages holding a range are faulted in by the call, so filling the range
// afterwards takes no page fault; pages outside it are left alone.
#include "points/huge_page_buffer.hpp"

#include <cstring>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/resource.h>

namespace omicron {
namespace {

constexpr std::size_t kPage = 4096;

long minorFaults() {
    rusage usage{};
    getrusage(RUSAGE_THREAD, &usage);
    return usage.ru_minflt;
}

TEST(PopulatePages, TheRangeIsFaultedInAndTheRestIsNot) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "a sanitizer's shadow memory takes page faults of its own";
#endif
    constexpr std::size_t kPages = 64;
    void* memory =
        mmap(nullptr, kPages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(memory, MAP_FAILED);
    madvise(memory, kPages * kPage, MADV_NOHUGEPAGE);
    auto* bytes = static_cast<std::uint8_t*>(memory);

    // From the middle of page 3 to the middle of page 20: pages 3-20.
    std::uint8_t* begin = bytes + 3 * kPage + 100;
    const std::size_t length = 17 * kPage;
    populatePages(begin, length);
    const long before = minorFaults();
    std::memset(begin, 0x5a, length);
    EXPECT_EQ(minorFaults(), before) << "filling a populated range took page faults";
    // Page 30 was not populated: its first write faults.
    bytes[30 * kPage] = 1;
    EXPECT_EQ(minorFaults(), before + 1);
    EXPECT_EQ(begin[length - 1], 0x5a);

    populatePages(begin, 0); // nothing to do
    munmap(memory, kPages * kPage);
}

} // namespace
} // namespace omicron
