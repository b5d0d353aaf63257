// Loads and stores of trivially copyable values at any byte address (memcpy: no alignment or
// aliasing assumptions), for the little-endian file formats this host reads and writes as is
// (every format's code asserts a little-endian host).
#pragma once

#include <cstdint>
#include <cstring>

namespace omicron {

template <typename T> T loadRaw(const std::uint8_t* at) {
    T value;
    std::memcpy(&value, at, sizeof(T));
    return value;
}

template <typename T> void storeRaw(std::uint8_t* at, const T& value) {
    std::memcpy(at, &value, sizeof(T));
}

} // namespace omicron
