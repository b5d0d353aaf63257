// The sorter's bin blocks: distinct page-aligned blocks across slabs, whose pages go back to
// the kernel when released (checked with mincore) while the others keep their contents.
#include "sort/bin_block_pool.hpp"

#include <cstdint>
#include <cstring>
#include <gtest/gtest.h>
#include <set>
#include <sys/mman.h>
#include <unistd.h>
#include <vector>

namespace omicron {
namespace {

constexpr std::size_t kBlockBytes = 16384;

// Resident pages of [block, block + kBlockBytes).
std::size_t residentPages(const void* block) {
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    std::vector<unsigned char> flags(kBlockBytes / page);
    EXPECT_EQ(mincore(const_cast<void*>(block), kBlockBytes, flags.data()), 0);
    std::size_t resident = 0;
    for (const unsigned char flag : flags) {
        resident += flag & 1u;
    }
    return resident;
}

TEST(BinBlockPool, BlocksAreDistinctAlignedAndSpanSlabs) {
    BinBlockPool pool(kBlockBytes);
    std::vector<std::uint32_t*> blocks;
    std::set<std::uintptr_t> seen;
    for (std::size_t i = 0; i < 2100; ++i) { // three slabs of 1024 blocks
        auto* block = static_cast<std::uint32_t*>(pool.allocate());
        const auto address = reinterpret_cast<std::uintptr_t>(block);
        EXPECT_EQ(address % 4096, 0u);
        EXPECT_TRUE(seen.insert(address).second);
        block[0] = static_cast<std::uint32_t>(i);
        block[kBlockBytes / sizeof(std::uint32_t) - 1] = static_cast<std::uint32_t>(~i);
        blocks.push_back(block);
    }
    // No two blocks overlap.
    for (auto it = std::next(seen.begin()); it != seen.end(); ++it) {
        EXPECT_GE(*it - *std::prev(it), kBlockBytes);
    }
    for (std::size_t i = 0; i < blocks.size(); ++i) {
        ASSERT_EQ(blocks[i][0], static_cast<std::uint32_t>(i));
        ASSERT_EQ(blocks[i][kBlockBytes / sizeof(std::uint32_t) - 1],
                  static_cast<std::uint32_t>(~i));
    }
}

TEST(BinBlockPool, ReleasedBlocksGiveTheirPagesBackAndOthersKeepTheirs) {
    BinBlockPool pool(kBlockBytes);
    std::vector<std::uint8_t*> blocks;
    for (int i = 0; i < 4; ++i) {
        auto* block = static_cast<std::uint8_t*>(pool.allocate());
        EXPECT_EQ(residentPages(block), 0u) << "a fresh block costs no memory";
        std::memset(block, 0x40 + i, kBlockBytes);
        EXPECT_EQ(residentPages(block), kBlockBytes / 4096);
        blocks.push_back(block);
    }
    ASSERT_EQ(blocks[1], blocks[0] + kBlockBytes); // one slab: adjacent
    ASSERT_EQ(blocks[2], blocks[1] + kBlockBytes);
    pool.release({blocks[1], blocks[2]}); // two adjacent blocks: one call
    EXPECT_EQ(residentPages(blocks[1]), 0u);
    EXPECT_EQ(residentPages(blocks[2]), 0u);
    pool.release({blocks[3]});
    EXPECT_EQ(residentPages(blocks[3]), 0u);
    EXPECT_EQ(residentPages(blocks[0]), kBlockBytes / 4096);
    for (std::size_t i = 0; i < kBlockBytes; ++i) {
        ASSERT_EQ(blocks[0][i], 0x40);
    }
}

} // namespace
} // namespace omicron
