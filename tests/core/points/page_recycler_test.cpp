// PageRecycler: given-back pages back the recipient's next untouched pages, with their bytes;
// the donor reads zero afterwards; what is not used goes back to the kernel.
#include "points/page_recycler.hpp"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <gtest/gtest.h>
#include <memory>
#include <sstream>
#include <string>
#include <sys/mman.h>

namespace omicron {
namespace {

constexpr std::size_t kPage = kSmallPageBytes;

// An anonymous mapping of `pages` pages of `pageBytes`, aligned to them (and advised huge when
// they are huge pages), unmapped at the end.
struct Mapping {
    explicit Mapping(std::size_t pages, std::size_t pageBytes = kPage)
        : bytes(pages * pageBytes), spare(pageBytes - kPage) {
        void* memory = mmap(nullptr, bytes + spare, PROT_READ | PROT_WRITE,
                            MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        EXPECT_NE(memory, MAP_FAILED);
        mapped = static_cast<std::byte*>(memory);
        const auto aligned =
            (reinterpret_cast<std::uintptr_t>(memory) + pageBytes - 1) & ~(pageBytes - 1);
        data = reinterpret_cast<std::byte*>(aligned);
        if (pageBytes > kPage) {
            madvise(data, bytes, MADV_HUGEPAGE);
        }
    }
    ~Mapping() { munmap(mapped, bytes + spare); }
    std::uint8_t at(std::size_t offset) const {
        return std::to_integer<std::uint8_t>(data[offset]);
    }
    std::byte* mapped;
    std::byte* data;
    std::size_t bytes;
    std::size_t spare; // mapped beyond `bytes` to align them
};

TEST(PageRecycler, DonatedPagesBackTheRecipientsNextPages) {
    Mapping donor(8);
    Mapping recipient(16);
    for (std::size_t page = 0; page < 8; ++page) {
        std::memset(donor.data + page * kPage, static_cast<int>(page + 1), kPage);
    }
    PageRecycler recycler({recipient.data, recipient.bytes});
    // Pages 2-4 of the donor; the partial pages around them stay with it.
    recycler.donate(donor.data + 2 * kPage - 100, 3 * kPage + 200);
    recycler.prepare(recipient.data + 2 * kPage + 1); // pages 0-2 are about to be written
    EXPECT_EQ(recycler.pagesMoved(), 3u);
    // The recipient's pages are the donor's, bytes and all (the writer overwrites them).
    EXPECT_EQ(recipient.at(0), 3);
    EXPECT_EQ(recipient.at(kPage + 7), 4);
    EXPECT_EQ(recipient.at(3 * kPage - 1), 5);
    EXPECT_EQ(recipient.at(3 * kPage), 0); // not prepared: untouched
    // The donor's moved pages read as zero; the others kept their bytes.
    EXPECT_EQ(donor.at(2 * kPage), 0);
    EXPECT_EQ(donor.at(5 * kPage - 1), 0);
    EXPECT_EQ(donor.at(2 * kPage - 1), 2);
    EXPECT_EQ(donor.at(5 * kPage), 6);
}

TEST(PageRecycler, APageAlreadyPreparedIsNeverReplaced) {
    Mapping donor(8);
    Mapping recipient(16);
    std::memset(donor.data, 0x5a, donor.bytes);
    PageRecycler recycler({recipient.data, recipient.bytes});
    recycler.prepare(recipient.data + 10); // nothing to move: page 0 faults in
    recipient.data[0] = std::byte{0x11};
    recycler.donate(donor.data, 2 * kPage);
    recycler.prepare(recipient.data + kPage + 1); // page 0 stays, page 1 is the donor's
    EXPECT_EQ(recipient.at(0), 0x11);
    EXPECT_EQ(recipient.at(kPage), 0x5a);
    EXPECT_EQ(recycler.pagesMoved(), 1u);
    // The donation's second page waits for the next prepare, and adjacent donations join:
    // pages 2 and 3 come in one move.
    recycler.donate(donor.data + 2 * kPage, 2 * kPage);
    recycler.prepare(recipient.data + 4 * kPage);
    EXPECT_EQ(recycler.pagesMoved(), 3u);
    EXPECT_EQ(recycler.moves(), 2u);
    EXPECT_EQ(recipient.at(4 * kPage - 1), 0x5a);
}

TEST(PageRecycler, WhatNoRecipientPageNeedsGoesBackToTheKernel) {
    Mapping donor(8);
    Mapping recipient(2);
    std::memset(donor.data, 0x77, donor.bytes);
    {
        PageRecycler recycler({recipient.data, recipient.bytes});
        recycler.donate(donor.data, 8 * kPage);
        recycler.prepare(recipient.data + 100 * kPage); // clamped to the recipient's 2 pages
        EXPECT_EQ(recycler.pagesMoved(), 2u);
        EXPECT_EQ(donor.at(3 * kPage), 0x77); // still donated, not yet given back
    }
    // Nothing of the donor is resident any more (checked before reading maps zero pages in).
    unsigned char resident[8];
    ASSERT_EQ(mincore(donor.data, donor.bytes, resident), 0);
    for (std::size_t page = 0; page < 8; ++page) {
        EXPECT_EQ(resident[page] & 1, 0) << "page " << page << " still resident";
    }
    for (std::size_t page = 0; page < 8; ++page) {
        EXPECT_EQ(donor.at(page * kPage), 0) << page;
    }
}

TEST(PageRecycler, MovesStopAtTheMappingLimitAndPagesGoBack) {
    // Every other page donated: each donation is a move (and a mapping) of its own.
    const std::size_t donations = PageRecycler::kMaxMoves + 10;
    Mapping donor(2 * donations);
    Mapping recipient(donations);
    std::memset(donor.data, 0x33, donor.bytes);
    PageRecycler recycler({recipient.data, recipient.bytes});
    for (std::size_t i = 0; i < donations; ++i) {
        recycler.donate(donor.data + 2 * i * kPage, kPage);
    }
    recycler.prepare(recipient.data + recipient.bytes);
    EXPECT_EQ(recycler.moves(), PageRecycler::kMaxMoves);
    EXPECT_EQ(recipient.at((PageRecycler::kMaxMoves - 1) * kPage), 0x33);
    EXPECT_EQ(recipient.at(PageRecycler::kMaxMoves * kPage), 0); // faulted in, not moved
    EXPECT_EQ(donor.at(2 * (donations - 1) * kPage), 0);         // given back
    recycler.donate(donor.data + kPage, kPage);                  // from now on: given back
    EXPECT_EQ(donor.at(kPage), 0);
}

// AnonHugePages (KiB) of the mapping that holds `address`, from /proc/self/smaps.
std::size_t anonHugeKiB(const void* address) {
    std::ifstream smaps("/proc/self/smaps");
    const auto at = reinterpret_cast<std::uintptr_t>(address);
    bool inside = false;
    for (std::string line; std::getline(smaps, line);) {
        std::uintptr_t begin = 0;
        std::uintptr_t end = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> begin >> dash >> end && dash == '-') {
            inside = begin <= at && at < end;
        } else if (inside && line.rfind("AnonHugePages:", 0) == 0) {
            return std::stoul(line.substr(14));
        }
    }
    return 0;
}

// On huge pages a whole 2 MiB page moves, with its bytes, and stays one huge page (the kernel
// moves its one table entry); the partial pages around a donation stay with the donor.
TEST(PageRecycler, HugePagesMoveWholeAndStayHuge) {
    Mapping donor(3, kHugePageBytes);
    Mapping recipient(4, kHugePageBytes);
    for (std::size_t page = 0; page < 3; ++page) {
        std::memset(donor.data + page * kHugePageBytes, static_cast<int>(page + 1), kHugePageBytes);
    }
    const bool donorHuge = anonHugeKiB(donor.data + kHugePageBytes) >= 2048;
    PageRecycler recycler({recipient.data, recipient.bytes}, kHugePageBytes);
    // Half of page 0, page 1 whole, half of page 2: only page 1 is donated.
    recycler.donate(donor.data + kHugePageBytes / 2, 2 * kHugePageBytes);
    recycler.prepare(recipient.data + 1); // the recipient's page 0 is about to be written
    EXPECT_EQ(recycler.pagesMoved(), kHugePageBytes / kPage);
    EXPECT_EQ(recycler.moves(), 1u);
    EXPECT_EQ(recipient.at(0), 2);
    EXPECT_EQ(recipient.at(kHugePageBytes - 1), 2);
    EXPECT_EQ(donor.at(kHugePageBytes), 0);
    EXPECT_EQ(donor.at(kHugePageBytes - 1), 1);
    EXPECT_EQ(donor.at(2 * kHugePageBytes), 3);
    if (donorHuge) {
        EXPECT_GE(anonHugeKiB(recipient.data), 2048u) << "the move split the huge page";
    }
    recycler.prepare(recipient.data + kHugePageBytes + 1); // nothing donated: faulted in
    EXPECT_EQ(recycler.pagesMoved(), kHugePageBytes / kPage);
    EXPECT_EQ(recipient.at(kHugePageBytes), 0);
}

} // namespace
} // namespace omicron
