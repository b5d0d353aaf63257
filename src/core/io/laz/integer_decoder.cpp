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

SymbolModel& IntegerDecoder::correctorModel(std::uint32_t k) {
    std::unique_ptr<SymbolModel>& model = m_correctorModels[k];
    if (!model) {
        const std::uint32_t codedBits = k <= m_bitsHigh ? k : m_bitsHigh;
        model = std::make_unique<SymbolModel>(std::uint32_t{1} << codedBits);
    }
    return *model;
}

std::int32_t IntegerDecoder::readCorrector(ArithmeticDecoder& decoder, SymbolModel& classModel) {
    m_k = decoder.decodeSymbol(classModel);
    if (m_k == 0) {
        return static_cast<std::int32_t>(decoder.decodeBit(m_corrector0));
    }
    if (m_k >= 32) {
        return m_correctorMin;
    }
    std::uint32_t corrector = decoder.decodeSymbol(correctorModel(m_k));
    if (m_k > m_bitsHigh) {
        const std::uint32_t rawBits = m_k - m_bitsHigh;
        corrector = (corrector << rawBits) | decoder.readBits(rawBits);
    }
    // Class k holds [-(2^k - 1), -2^(k-1)] and [2^(k-1) + 1, 2^k], coded as [0, 2^k).
    if (corrector >= (std::uint32_t{1} << (m_k - 1))) {
        return static_cast<std::int32_t>(corrector + 1);
    }
    return static_cast<std::int32_t>(corrector - ((std::uint32_t{1} << m_k) - 1));
}

std::int32_t IntegerDecoder::decode(ArithmeticDecoder& decoder, std::int32_t prediction,
                                    std::uint32_t context) {
    assert(context < m_classModels.size());
    const std::int32_t corrector = readCorrector(decoder, m_classModels[context]);
    // Unsigned arithmetic: the sum wraps like the encoder's 32-bit registers.
    std::uint32_t value =
        static_cast<std::uint32_t>(prediction) + static_cast<std::uint32_t>(corrector);
    if (static_cast<std::int32_t>(value) < 0) {
        value += m_correctorRange;
    } else if (m_correctorRange != 0 && value >= m_correctorRange) {
        value -= m_correctorRange;
    }
    return static_cast<std::int32_t>(value);
}

} // namespace omicron::laz
