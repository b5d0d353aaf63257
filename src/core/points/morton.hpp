// Morton codes with a leading sentinel bit: the addressing scheme of the whole octree.
//
// A code at level l holds 3*l interleaved bits below a single sentinel 1 bit, so codes of
// different levels never collide: the root is 1, its children are 0b1000..0b1111. Within a
// triple, bit 0 is x, bit 1 is y and bit 2 is z (the same everywhere in omicron). 64-bit codes
// reach level 21 (1 + 3*21 = 64 bits). Points are sorted once at level 21; any shallower depth
// is a prefix of that order (codeAtLevel).
#pragma once

#include <array>
#include <bit>
#include <cassert>
#include <cstdint>

namespace omicron::morton {

using Code = std::uint64_t;

inline constexpr int kMaxLevel = 21;
inline constexpr std::uint32_t kCellsPerAxis = 1u << kMaxLevel; // at kMaxLevel
inline constexpr Code kRoot = 1;

namespace detail {
// spread8[v]: the 8 bits of v moved so that bit i lands at bit 3*i.
constexpr std::array<Code, 256> makeSpread8Table() {
    std::array<Code, 256> table{};
    for (std::uint32_t v = 0; v < 256; ++v) {
        for (int bit = 0; bit < 8; ++bit) {
            table[v] |= Code((v >> bit) & 1u) << (3 * bit);
        }
    }
    return table;
}
inline constexpr std::array<Code, 256> kSpread8 = makeSpread8Table();

// Spreads the low 21 bits of v so that bit i lands at bit 3*i. A byte table beat the
// "magic bits" shift-and-mask sequence by ~1.4x in bench/morton_bench on this project's
// machines (no BMI2 pdep assumed).
constexpr Code spreadBits3(std::uint32_t v) {
    return kSpread8[v & 0xffu] | kSpread8[(v >> 8) & 0xffu] << 24 |
           kSpread8[(v >> 16) & 0x1fu] << 48;
}

// The same spread in five shift-and-mask steps ("magic bits"). Slower than the table one
// point at a time, but each step is a few vector instructions over 64-bit lanes, where the
// table would need gathers: the batch encoder (morton_batch.hpp) spreads with it.
constexpr Code spreadBits3Shifts(std::uint32_t v) {
    Code x = v & 0x1fffffu;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

// Inverse of spreadBits3: gathers every third bit (starting at bit 0) into the low 21 bits.
constexpr std::uint32_t compactBits3(Code x) {
    x &= 0x1249249249249249ull;
    x = (x ^ (x >> 2)) & 0x10c30c30c30c30c3ull;
    x = (x ^ (x >> 4)) & 0x100f00f00f00f00full;
    x = (x ^ (x >> 8)) & 0x1f0000ff0000ffull;
    x = (x ^ (x >> 16)) & 0x1f00000000ffffull;
    x = (x ^ (x >> 32)) & 0x1fffffull;
    return static_cast<std::uint32_t>(x);
}
} // namespace detail

struct Cell {
    std::uint32_t x = 0, y = 0, z = 0;
    friend constexpr bool operator==(const Cell&, const Cell&) = default;
};

// Level of a valid code (sentinel bit present): (63 - clz) / 3.
constexpr int level(Code code) {
    assert(code != 0);
    return (63 - std::countl_zero(code)) / 3;
}

constexpr bool isValid(Code code) {
    return code != 0 && (63 - std::countl_zero(code)) % 3 == 0;
}

// Code of the cell (x, y, z) at `lvl`; each coordinate must be < 2^lvl.
constexpr Code encode(Cell cell, int lvl) {
    assert(lvl >= 0 && lvl <= kMaxLevel);
    assert(lvl == kMaxLevel || (cell.x >> lvl) == 0);
    assert(lvl == kMaxLevel || (cell.y >> lvl) == 0);
    assert(lvl == kMaxLevel || (cell.z >> lvl) == 0);
    const Code bits = detail::spreadBits3(cell.x) | detail::spreadBits3(cell.y) << 1 |
                      detail::spreadBits3(cell.z) << 2;
    return (Code{1} << (3 * lvl)) | bits;
}

// Cell coordinates of a code at its own level.
constexpr Cell decode(Code code) {
    const Code bits = code & ~(Code{1} << (3 * level(code)));
    return {detail::compactBits3(bits), detail::compactBits3(bits >> 1),
            detail::compactBits3(bits >> 2)};
}

constexpr Code parent(Code code) {
    assert(code > kRoot);
    return code >> 3;
}

// childIndex in 0..7: bit 0 = +x half, bit 1 = +y half, bit 2 = +z half.
constexpr Code child(Code code, unsigned childIndex) {
    assert(childIndex < 8 && level(code) < kMaxLevel);
    return code << 3 | childIndex;
}

constexpr unsigned childIndex(Code code) {
    assert(code > kRoot);
    return static_cast<unsigned>(code & 7u);
}

// The ancestor of `code` at the shallower (or equal) level `lvl`: a prefix of the code.
constexpr Code codeAtLevel(Code code, int lvl) {
    assert(lvl >= 0 && lvl <= level(code));
    return code >> (3 * (level(code) - lvl));
}

// Right-most descendant of `code` at level `maxLevel`: span(y) <= span(x) for every
// descendant y of x, which orders subtrees by where they end in the sorted stream.
constexpr Code span(Code code, int maxLevel) {
    const int k = maxLevel - level(code);
    assert(k >= 0);
    return (code << (3 * k)) | ((Code{1} << (3 * k)) - 1);
}

// Placeholder of a node one level down: its right-most child slot. Applied repeatedly it
// reaches span(code, maxLevel), which is where a shallow leaf waits in the sorted order.
constexpr Code placeholder(Code code) {
    assert(level(code) < kMaxLevel);
    return code << 3 | 0b111u;
}

// True if `ancestor` is `code` itself or one of its ancestors.
constexpr bool isAncestorOrSelf(Code ancestor, Code code) {
    const int la = level(ancestor);
    const int lc = level(code);
    return la <= lc && (code >> (3 * (lc - la))) == ancestor;
}

// Cell index along one axis at kMaxLevel for a coordinate in the unit interval. The closed
// interval [0, 1] maps onto 2^21 cells: 1.0 (the max face) lands in the last cell instead of
// wrapping to the next, and anything outside (rounding) is clamped.
constexpr std::uint32_t quantize(float unit) {
    // Branch-free (maxss/minss): this runs once per coordinate of every point.
    const float scaled = unit * static_cast<float>(kCellsPerAxis);
    const float positive = scaled > 0.0f ? scaled : 0.0f; // NaN compares false -> 0
    const float lastCell = static_cast<float>(kCellsPerAxis - 1);
    // Through a signed conversion, which every vector width has (the batch encoder's loop
    // vectorises this): the clamped value is in [0, 2^21 - 1], where both truncate the same.
    return static_cast<std::uint32_t>(
        static_cast<std::int32_t>(positive < lastCell ? positive : lastCell));
}

// Level-21 code of a point in the unit cube.
constexpr Code encodeUnit(float x, float y, float z) {
    return encode({quantize(x), quantize(y), quantize(z)}, kMaxLevel);
}

} // namespace omicron::morton
