#include "io/laz/byte_decoder.hpp"

#include <algorithm>

namespace omicron::laz {

ByteDecoder::ByteDecoder(std::size_t byteCount) : m_last(byteCount) {
    m_models.reserve(byteCount);
    for (std::size_t i = 0; i < byteCount; ++i) {
        m_models.emplace_back(256);
    }
}

void ByteDecoder::start(const std::uint8_t* item) {
    std::copy_n(item, m_last.size(), m_last.begin());
}

void ByteDecoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    for (std::size_t i = 0; i < m_last.size(); ++i) {
        m_last[i] = static_cast<std::uint8_t>(m_last[i] + decoder.decodeSymbol(m_models[i]));
        item[i] = m_last[i];
    }
}

} // namespace omicron::laz
