// PLY body values: binary scalars of any type and byte order, their conversion to our
// attributes, and a cursor for binary records whose size varies (lists).
#pragma once

#include "io/file_stream.hpp"
#include "io/ply/ply_header.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace omicron {

// The scalar of `type` at `bytes` (unaligned), byte-swapped when the file's byte order is not
// the machine's.
double loadPlyScalar(const std::uint8_t* bytes, PlyScalarType type, bool swapBytes);

// 8-bit colour channel from a value of any PLY type: uchar as is, ushort scaled (65535 ->
// 255), float/double as 0..1 fractions, other integer types as 0..255 values. Clamped and
// rounded; NaN gives 0. Inline: the fast PLY loops call it per channel for float colours.
inline std::uint8_t plyColorChannel(double value, PlyScalarType type) {
    double scaled = value;
    if (type == PlyScalarType::Float32 || type == PlyScalarType::Float64) {
        scaled = value * 255.0;
    } else if (type == PlyScalarType::UInt16) {
        scaled = value / 257.0;
    }
    if (!(scaled > 0.0)) {
        return 0;
    }
    return scaled >= 255.0 ? 255 : static_cast<std::uint8_t>(scaled + 0.5);
}

// 16-bit intensity, clamped and rounded; NaN gives 0. Inline: the fast PLY loops call it per
// point for a float intensity.
inline std::uint16_t plyIntensity(double value) {
    if (!(value > 0.0)) {
        return 0;
    }
    return value >= 65535.0 ? 65535 : static_cast<std::uint16_t>(value + 0.5);
}

// Walks a binary body value by value with the file offset of every value known; skipping list
// items beyond the buffer seeks instead of reading.
class PlyBodyCursor {
public:
    PlyBodyCursor(FileStream& stream, std::uint64_t start);

    std::uint64_t offset() const { return m_bufferOffset + m_begin; }

    // `count` (<= 8) contiguous bytes, consumed; nullptr when the file ends first.
    const std::uint8_t* take(std::size_t count) {
        if (m_end - m_begin < count && !refill(count)) {
            return nullptr;
        }
        const std::uint8_t* bytes = m_buffer.data() + m_begin;
        m_begin += count;
        return bytes;
    }

    // False when the file ends before `count` more bytes.
    bool skip(std::uint64_t count);

private:
    bool refill(std::size_t count);

    FileStream& m_stream;
    std::vector<std::uint8_t> m_buffer;
    std::size_t m_begin = 0;          // next unread byte in m_buffer
    std::size_t m_end = 0;            // one past the last valid byte
    std::uint64_t m_bufferOffset = 0; // file offset of m_buffer[0]
};

} // namespace omicron
