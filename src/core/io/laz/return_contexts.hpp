// The return contexts LAZ predicts coordinates and intensities in: a point's number of
// returns n and return number r select which recent differences (the "map") and which last
// height (the "level") it is predicted from. The tables also give a context to the
// inconsistent (n, r) pairs real files contain (r > n, numbering from 0), so they are data of
// the format, copied from its definition.
#pragma once

#include <array>
#include <cstdint>

namespace omicron::laz {

// POINT10 (n, r < 8): 16 contexts of recent x/y differences and intensities.
inline std::uint32_t returnMap8(std::uint32_t n, std::uint32_t r) {
    static constexpr std::array<std::array<std::uint8_t, 8>, 8> kMap = {{
        {15, 14, 13, 12, 11, 10, 9, 8},
        {14, 0, 1, 3, 6, 10, 10, 9},
        {13, 1, 2, 4, 7, 11, 11, 10},
        {12, 3, 4, 5, 8, 12, 12, 11},
        {11, 6, 7, 8, 9, 13, 13, 12},
        {10, 10, 11, 12, 13, 14, 14, 13},
        {9, 10, 11, 12, 13, 14, 15, 14},
        {8, 9, 10, 11, 12, 13, 14, 15},
    }};
    return kMap[n & 7][r & 7];
}

// POINT10: 8 last heights, by how far the return is from the last one (|n - r|).
inline std::uint32_t returnLevel8(std::uint32_t n, std::uint32_t r) {
    n &= 7;
    r &= 7;
    return n > r ? n - r : r - n;
}

// POINT14 (n, r < 16): 6 contexts (times 2 for "GPS time changed") of recent differences.
inline std::uint32_t returnMap6(std::uint32_t n, std::uint32_t r) {
    static constexpr std::array<std::array<std::uint8_t, 16>, 16> kMap = {{
        {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5},
        {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
        {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3},
        {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
        {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
        {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
        {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4},
        {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
        {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4},
        {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
        {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5},
    }};
    return kMap[n & 15][r & 15];
}

// POINT14: 8 last heights, by |n - r| capped at 7.
inline std::uint32_t returnLevel8Of16(std::uint32_t n, std::uint32_t r) {
    n &= 15;
    r &= 15;
    const std::uint32_t distance = n > r ? n - r : r - n;
    return distance < 7 ? distance : 7;
}

} // namespace omicron::laz
