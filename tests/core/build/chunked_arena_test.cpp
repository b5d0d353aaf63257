// The chunked arena: elements never move while it grows, push_back and extend/slot append in
// order, and elements a pool of threads writes through slot() are what a reader sees once the
// count covering them is published (the builder's leaves and insertion log).
#include "build/chunked_arena.hpp"

#include <atomic>
#include <cstdint>
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <thread>
#include <vector>

namespace omicron {
namespace {

struct Entry {
    std::uint64_t key;
    std::uint32_t check;
};

Entry entryFor(std::size_t index) {
    return {index * 7919, static_cast<std::uint32_t>(index ^ 0x5a5a5a5au)};
}

TEST(ChunkedArena, PushBackAndExtendAppendInOrderAndNothingMoves) {
    ChunkedArena<Entry, 16> arena(1000);
    std::vector<const Entry*> addresses;
    std::size_t next = 0;
    // Appends of every size around the chunk size, alternating the two ways to append.
    for (std::size_t count = 1; next + count <= arena.capacity(); ++count) {
        if (count % 2 == 0) {
            ASSERT_EQ(arena.extend(count), next);
            for (std::size_t i = next; i < next + count; ++i) {
                arena.slot(i) = entryFor(i);
            }
        } else {
            for (std::size_t i = next; i < next + count; ++i) {
                ASSERT_EQ(arena.push_back(entryFor(i)), i);
            }
        }
        next += count;
        ASSERT_EQ(arena.size(), next);
        for (std::size_t i = addresses.size(); i < next; ++i) {
            addresses.push_back(&arena[i]);
        }
    }
    for (std::size_t i = 0; i < arena.size(); ++i) {
        EXPECT_EQ(&arena[i], addresses[i]) << "element " << i << " moved";
        EXPECT_EQ(arena[i].key, entryFor(i).key);
        EXPECT_EQ(arena[i].check, entryFor(i).check);
    }
    const std::size_t chunks = (arena.size() + 15) / 16;
    EXPECT_GE(arena.bytesAllocated(), chunks * 16 * sizeof(Entry));
    EXPECT_LT(arena.bytesAllocated(), (chunks + 1) * 16 * sizeof(Entry) + 1000);
    // extend(0) appends nothing and allocates nothing.
    const std::size_t bytes = arena.bytesAllocated();
    EXPECT_EQ(arena.extend(0), arena.size());
    EXPECT_EQ(arena.bytesAllocated(), bytes);
}

TEST(ChunkedArena, ReaderSeesWholeElementsThatWorkersWroteBeforePublication) {
    constexpr std::size_t kCapacity = 200000;
    ChunkedArena<Entry, 1024> arena(kCapacity);
    std::atomic<std::size_t> published{0};
    std::atomic<bool> done{false};
    std::thread reader([&] {
        std::size_t seen = 0;
        while (!done.load(std::memory_order_acquire) || seen < kCapacity) {
            const std::size_t count = published.load(std::memory_order_acquire);
            for (; seen < count; ++seen) {
                const Entry& entry = arena[seen];
                ASSERT_EQ(entry.key, entryFor(seen).key) << seen;
                ASSERT_EQ(entry.check, entryFor(seen).check) << seen;
            }
        }
    });
    for (std::size_t first = 0; first < kCapacity;) {
        const std::size_t count = std::min<std::size_t>(kCapacity - first, 1 + first % 5000);
        ASSERT_EQ(arena.extend(count), first);
        tbb::parallel_for(first, first + count,
                          [&](std::size_t i) { arena.slot(i) = entryFor(i); });
        first += count;
        published.store(first, std::memory_order_release);
    }
    done.store(true, std::memory_order_release);
    reader.join();
}

} // namespace
} // namespace omicron
