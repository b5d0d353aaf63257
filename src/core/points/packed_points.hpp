// Positions and colours of a Morton-sorted cloud, quantised to the level-21 grid and bit-packed
// in blocks of 64 points: the "packed" point store (about 7 bytes a point where floats and
// bytes take 15).
//
// Why it is small: a point's position is kept as its level-21 cell along each axis — exactly
// what morton::quantize gives and the sorter sorted by, so a point keeps its code, its place in
// the order and its leaf — and decodes to that cell's centre (at most half a level-21 cell, a
// 2^-22 of the cube's edge, from where it was read). Points in Morton order are spatially
// coherent, so the cells of a block of 64 consecutive points lie in a small box: each block
// stores its minimum per axis (and per colour channel) and every point the differences, in as
// many bits as the block's spread needs (frame-of-reference packing). Every point of a block
// takes the same number of bits, so any point decodes in O(1), without touching its neighbours.
//
// Concurrency: one producer appends (in Morton order, like SortedCloud's prefix); readers decode
// any point below a count published to them with release/acquire (SortedCloud::sortedEnd). A
// block is never changed in place: the block that ends an append is usually short, and when the
// next append fills it, it is encoded anew elsewhere and its table entry swapped (release), so a
// reader still holding the short one reads valid bytes. The short versions stay allocated until
// the store dies (one block per append at most).
#pragma once

#include "points/morton.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <glm/vec3.hpp>
#include <memory>
#include <span>
#include <vector>

namespace omicron {

class PackedPointStore {
public:
    static constexpr std::size_t kBlockPoints = 64;
    // A decoded position is the centre of its level-21 cell: this far from the read one at most
    // along each axis, in unit-cube units.
    static constexpr float kMaxError = 0.5f / static_cast<float>(morton::kCellsPerAxis);

    PackedPointStore(std::size_t capacity, bool hasColors);
    PackedPointStore(const PackedPointStore&) = delete;
    PackedPointStore& operator=(const PackedPointStore&) = delete;

    bool hasColors() const { return m_hasColors; }
    // Producer side: points appended so far (readers use the cloud's published count).
    std::size_t size() const { return m_size; }

    // Producer only: appends points (unit-cube positions, and colours when the store has them:
    // same length) after the ones already held. Encodes blocks in parallel.
    void append(std::span<const glm::vec3> positions, std::span<const glm::u8vec3> colors);

    glm::vec3 position(std::size_t i) const {
        const Block block = blockOf(i);
        glm::vec3 p;
        std::size_t offset = (i % kBlockPoints) * block.header.recordBits;
        for (int axis = 0; axis < 3; ++axis) {
            const std::uint32_t cell =
                block.header.base[axis] + field(block.bits, offset, block.header.widths[axis]);
            // cell + 0.5 needs 22 bits of mantissa and the scale is a power of two: exact.
            p[axis] = (static_cast<float>(cell) + 0.5f) * kCellEdge;
            offset += block.header.widths[axis];
        }
        return p;
    }

    glm::u8vec3 color(std::size_t i) const {
        const Block block = blockOf(i);
        std::size_t offset = (i % kBlockPoints) * block.header.recordBits +
                             block.header.widths[0] + block.header.widths[1] +
                             block.header.widths[2];
        glm::u8vec3 c;
        for (int channel = 0; channel < 3; ++channel) {
            const int width = block.header.widths[3 + channel];
            c[channel] = static_cast<std::uint8_t>(block.header.colorBase[channel] +
                                                   field(block.bits, offset, width));
            offset += width;
        }
        return c;
    }

    // Asks for the cache lines of the blocks holding published points [first, first + count):
    // a block's header and about 7 bytes a point (the typical record; a wider block's tail is
    // left to the hardware).
    void prefetch(std::size_t first, std::size_t count) const {
        constexpr std::size_t kTypicalBlockBytes = sizeof(Header) + 7 * kBlockPoints;
        for (std::size_t block = first / kBlockPoints; block * kBlockPoints < first + count;
             ++block) {
            const char* at =
                reinterpret_cast<const char*>(m_blocks[block].load(std::memory_order_acquire));
            for (std::size_t line = 0; line < kTypicalBlockBytes; line += 64) {
                __builtin_prefetch(at + line);
            }
        }
    }

    // Everything the store holds: block bytes (superseded short blocks included) and the table.
    // Any thread may ask, while the producer appends.
    std::size_t bytesResident() const;

private:
    static constexpr float kCellEdge = 1.0f / static_cast<float>(morton::kCellsPerAxis);

    // Stored unaligned in front of the block's bits (read with memcpy).
    struct Header {
        std::uint32_t base[3];     // smallest level-21 cell per axis
        std::uint8_t colorBase[3]; // smallest value per channel
        std::uint8_t widths[6];    // bits per point: x, y, z, red, green, blue
        std::uint8_t recordBits;   // their sum: one point's record
    };
    struct Block {
        Header header;
        const std::byte* bits;
    };

    Block blockOf(std::size_t i) const {
        const std::byte* at = m_blocks[i / kBlockPoints].load(std::memory_order_acquire);
        Block block;
        std::memcpy(&block.header, at, sizeof(Header));
        block.bits = at + sizeof(Header);
        return block;
    }

    // The `width`-bit field at bit `offset` (width <= 21: with the offset's 7 low bits it fits
    // the 64-bit load, which may read up to 7 bytes past the block: pages are padded for it).
    static std::uint32_t field(const std::byte* bits, std::size_t offset, int width) {
        std::uint64_t word;
        std::memcpy(&word, bits + offset / 8, sizeof(word));
        return static_cast<std::uint32_t>((word >> (offset % 8)) &
                                          ((std::uint64_t{1} << width) - 1));
    }

    static Header headerFor(std::span<const glm::vec3> positions,
                            std::span<const glm::u8vec3> colors);
    static std::size_t blockBytes(const Header& header, std::size_t points);
    static void encode(const Header& header, std::span<const glm::vec3> positions,
                       std::span<const glm::u8vec3> colors, std::byte* out);

    std::size_t m_capacity;
    bool m_hasColors;
    std::size_t m_size = 0;
    std::unique_ptr<std::atomic<const std::byte*>[]> m_blocks;
    std::vector<std::unique_ptr<std::byte[]>> m_pages; // one per append
    std::atomic<std::size_t> m_pageBytes{0}; // read by any thread (statistics)
    // The points of the short block that ended the last append, kept to encode it again, whole,
    // when the next append fills it (producer only).
    std::vector<glm::vec3> m_tailPositions;
    std::vector<glm::u8vec3> m_tailColors;
};

} // namespace omicron
