#include "io/ply/ply_values.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

namespace omicron {

namespace {

constexpr std::size_t kCursorBufferBytes = 1 << 20;

template <typename T> T loadValue(const std::uint8_t* bytes, bool swapBytes) {
    std::array<std::uint8_t, sizeof(T)> raw;
    std::memcpy(raw.data(), bytes, sizeof(T));
    if (swapBytes) {
        std::reverse(raw.begin(), raw.end());
    }
    return std::bit_cast<T>(raw);
}

} // namespace

double loadPlyScalar(const std::uint8_t* bytes, PlyScalarType type, bool swapBytes) {
    switch (type) {
    case PlyScalarType::Int8:
        return loadValue<std::int8_t>(bytes, false);
    case PlyScalarType::UInt8:
        return loadValue<std::uint8_t>(bytes, false);
    case PlyScalarType::Int16:
        return loadValue<std::int16_t>(bytes, swapBytes);
    case PlyScalarType::UInt16:
        return loadValue<std::uint16_t>(bytes, swapBytes);
    case PlyScalarType::Int32:
        return loadValue<std::int32_t>(bytes, swapBytes);
    case PlyScalarType::UInt32:
        return loadValue<std::uint32_t>(bytes, swapBytes);
    case PlyScalarType::Float32:
        return loadValue<float>(bytes, swapBytes);
    case PlyScalarType::Float64:
        return loadValue<double>(bytes, swapBytes);
    }
    return 0.0;
}

PlyBodyCursor::PlyBodyCursor(FileStream& stream, std::uint64_t start)
    : m_stream(stream), m_buffer(kCursorBufferBytes), m_bufferOffset(start) {
    m_stream.seek(start);
}

bool PlyBodyCursor::skip(std::uint64_t count) {
    const std::size_t buffered = m_end - m_begin;
    if (count <= buffered) {
        m_begin += static_cast<std::size_t>(count);
        return true;
    }
    const std::uint64_t target = offset() + count;
    if (target > m_stream.size()) {
        return false;
    }
    m_stream.seek(target);
    m_bufferOffset = target;
    m_begin = m_end = 0;
    return true;
}

bool PlyBodyCursor::refill(std::size_t count) {
    // Keep the unread tail, then append as much as the buffer holds.
    const std::size_t tail = m_end - m_begin;
    std::memmove(m_buffer.data(), m_buffer.data() + m_begin, tail);
    m_bufferOffset += m_begin;
    m_begin = 0;
    m_end = tail + m_stream.read(m_buffer.data() + tail, m_buffer.size() - tail);
    return m_end >= count;
}

} // namespace omicron
