// The sorter's bin blocks: distinct page-aligned blocks across slabs; a slab's pages go back to
// the kernel when its last block is released (checked with mincore), and until then every
// block keeps its contents.
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

TEST(BinBlockPool, ASlabsPagesGoBackWhenItsLastBlockIsGivenBack) {
    BinBlockPool pool(kBlockBytes);
    constexpr std::size_t perSlab = BinBlockPool::kBlocksPerSlab;
    std::vector<std::uint8_t*> blocks;
    for (std::size_t i = 0; i < perSlab + 3; ++i) { // a full slab and three blocks of a second
        auto* block = static_cast<std::uint8_t*>(pool.allocate());
        if (i < 4) {
            EXPECT_EQ(residentPages(block), 0u) << "a fresh block costs no memory";
        }
        std::memset(block, static_cast<int>(i % 251), kBlockBytes);
        blocks.push_back(block);
    }
    ASSERT_EQ(pool.slabCount(), 2u);
    ASSERT_EQ(blocks[1], blocks[0] + kBlockBytes); // one slab: adjacent

    // All of the first slab's blocks but block 5, in reverse order: nothing goes back, and
    // every block keeps its contents.
    std::vector<void*> firstSlab;
    for (std::size_t i = perSlab; i-- > 0;) {
        if (i != 5) {
            firstSlab.push_back(blocks[i]);
        }
    }
    pool.release(firstSlab);
    EXPECT_EQ(pool.releasedSlabCount(), 0u);
    for (std::size_t i = 0; i < perSlab; ++i) {
        ASSERT_EQ(residentPages(blocks[i]), kBlockBytes / 4096) << "block " << i;
        ASSERT_EQ(blocks[i][kBlockBytes - 1], i % 251);
    }
    // Its last block: the whole slab goes back, the second keeps its pages.
    pool.release({blocks[5]});
    EXPECT_EQ(pool.releasedSlabCount(), 1u);
    for (std::size_t i = 0; i < perSlab; ++i) {
        ASSERT_EQ(residentPages(blocks[i]), 0u) << "block " << i;
    }
    for (std::size_t i = perSlab; i < blocks.size(); ++i) {
        ASSERT_EQ(residentPages(blocks[i]), kBlockBytes / 4096);
        ASSERT_EQ(blocks[i][0], i % 251);
    }
    // The last slab, partly carved, goes back with the blocks carved from it.
    pool.release({blocks[perSlab + 2], blocks[perSlab]});
    EXPECT_EQ(pool.releasedSlabCount(), 1u);
    EXPECT_EQ(residentPages(blocks[perSlab]), kBlockBytes / 4096);
    pool.release({blocks[perSlab + 1]});
    EXPECT_EQ(pool.releasedSlabCount(), 2u);
    for (std::size_t i = perSlab; i < blocks.size(); ++i) {
        EXPECT_EQ(residentPages(blocks[i]), 0u);
    }
}

// Slabs advised huge pages (the sorter's, where they pay off): the same contents, and a slab's
// memory still goes back whole with its last block.
TEST(BinBlockPool, HugePageSlabsKeepContentsAndGoBackWhole) {
    BinBlockPool pool(kBlockBytes, PageSize::Huge);
    constexpr std::size_t perSlab = BinBlockPool::kBlocksPerSlab;
    std::vector<std::uint8_t*> blocks;
    for (std::size_t i = 0; i < perSlab + 1; ++i) {
        auto* block = static_cast<std::uint8_t*>(pool.allocate());
        std::memset(block, static_cast<int>(i % 251), kBlockBytes);
        blocks.push_back(block);
    }
    ASSERT_EQ(pool.slabCount(), 2u);
    std::vector<void*> firstSlab(blocks.begin(), blocks.begin() + perSlab);
    pool.release(firstSlab);
    EXPECT_EQ(pool.releasedSlabCount(), 1u);
    for (std::size_t i = 0; i < perSlab; ++i) {
        ASSERT_EQ(residentPages(blocks[i]), 0u) << "block " << i;
    }
    EXPECT_EQ(residentPages(blocks[perSlab]), kBlockBytes / 4096);
    EXPECT_EQ(blocks[perSlab][kBlockBytes - 1], perSlab % 251);
}

} // namespace
} // namespace omicron
