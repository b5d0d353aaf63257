#include "io/laz/rgb_decoder.hpp"

#include <bit>
#include <cstring>

static_assert(std::endian::native == std::endian::little, "LAS fields are stored with memcpy");

namespace omicron::laz {

void Rgb12Decoder::start(const std::uint8_t* item) {
    m_last = loadRgb(item);
}

void Rgb12Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    m_last = decodeRgb(decoder, m_models, m_last);
    storeRgb(item, m_last);
}

} // namespace omicron::laz
