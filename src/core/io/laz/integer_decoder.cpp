#include "io/laz/integer_decoder.hpp"

#include <cassert>
#include <limits>

namespace omicron::laz {

IntegerDecoder::IntegerDecoder(std::uint32_t bits, std::uint32_t contexts, std::uint32_t bitsHigh,
                               std::uint32_t range)
    : m_bitsHigh(bitsHigh) {
    assert(bits >= 1 && bits <= 32 && contexts >= 1);
    if (range != 0) {
        // The corrector needs as many bits as the range, one fewer for a power of two.
        m_correctorBits = 0;
        for (std::uint32_t rest = range; rest != 0; rest >>= 1) {
            ++m_correctorBits;
        }
        if (range == (std::uint32_t{1} << (m_correctorBits - 1))) {
            --m_correctorBits;
        }
        m_correctorRange = range;
        m_correctorMin = -static_cast<std::int32_t>(range / 2);
    } else if (bits < 32) {
        m_correctorBits = bits;
        m_correctorRange = std::uint32_t{1} << bits;
        m_correctorMin = -static_cast<std::int32_t>(m_correctorRange / 2);
    } else {
        m_correctorBits = 32;
        m_correctorRange = 0;
        m_correctorMin = std::numeric_limits<std::int32_t>::min();
    }
    m_classModels.reserve(contexts);
    for (std::uint32_t i = 0; i < contexts; ++i) {
        m_classModels.emplace_back(m_correctorBits + 1);
    }
    m_correctorModels.resize(m_correctorBits + 1);
}

} // namespace omicron::laz
