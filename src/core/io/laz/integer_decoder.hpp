// LAZ's integer "compressor", decoding side: a value is coded as its prediction plus a
// corrector. The corrector's magnitude class k (its bit length) is an adaptive symbol under
// one of several contexts; the corrector itself is a symbol of class k's model, its low bits
// raw beyond `bitsHigh` bits. Values wrap into the range of `bits` bits (or `range`).
#pragma once

#include "io/laz/arithmetic_decoder.hpp"

#include <cassert>
#include <cstdint>
#include <memory>
#include <vector>

namespace omicron::laz {

// a + b modulo 2^32, as the encoder's 32-bit registers add a coordinate and its difference.
inline std::int32_t wrappingAdd(std::int32_t a, std::int32_t b) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(b));
}

class IntegerDecoder {
public:
    // bits: width of the values (1..32); contexts: how many magnitude-class models the caller
    // chooses between; bitsHigh: corrector bits coded by a model, the rest raw; range: a
    // value range other than 2^bits (0: none). Constants of the format, asserted.
    explicit IntegerDecoder(std::uint32_t bits = 16, std::uint32_t contexts = 1,
                            std::uint32_t bitsHigh = 8, std::uint32_t range = 0);

    // The value whose prediction is `prediction`, under magnitude-class model `context`
    // (< contexts, asserted).
    std::int32_t decode(ArithmeticDecoder& decoder, std::int32_t prediction,
                        std::uint32_t context = 0);

    // The magnitude class of the last corrector: a context for the next coordinate.
    std::uint32_t k() const { return m_k; }

private:
    std::int32_t readCorrector(ArithmeticDecoder& decoder, SymbolModel& classModel);
    SymbolModel& correctorModel(std::uint32_t k);

    std::uint32_t m_bitsHigh;
    std::uint32_t m_correctorBits;
    std::uint32_t m_correctorRange; // 0: all 32 bits
    std::int32_t m_correctorMin;
    std::uint32_t m_k = 0;
    std::vector<SymbolModel> m_classModels; // one per context
    BitModel m_corrector0;                  // k = 0: the corrector is 0 or 1
    // k = 1..correctorBits; made on first use (most classes never occur in a chunk, and a
    // fresh model is what the encoder started from too).
    std::vector<std::unique_ptr<SymbolModel>> m_correctorModels;
};

// Inline: the layer loops that call these keep their decoder's state in registers.
inline SymbolModel& IntegerDecoder::correctorModel(std::uint32_t k) {
    std::unique_ptr<SymbolModel>& model = m_correctorModels[k];
    if (!model) {
        const std::uint32_t codedBits = k <= m_bitsHigh ? k : m_bitsHigh;
        model = std::make_unique<SymbolModel>(std::uint32_t{1} << codedBits);
    }
    return *model;
}

inline std::int32_t IntegerDecoder::readCorrector(ArithmeticDecoder& decoder,
                                                  SymbolModel& classModel) {
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

inline std::int32_t IntegerDecoder::decode(ArithmeticDecoder& decoder, std::int32_t prediction,
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
