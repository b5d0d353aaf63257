#include "io/laz/arithmetic_decoder.hpp"

namespace omicron::laz {

void ArithmeticDecoder::start(const std::uint8_t* begin, const std::uint8_t* end) {
    m_begin = begin;
    m_next = begin;
    m_end = end;
    m_missingBytes = 0;
    m_length = kMaxLength;
    m_value = nextByte() << 24;
    m_value |= nextByte() << 16;
    m_value |= nextByte() << 8;
    m_value |= nextByte();
}

} // namespace omicron::laz
