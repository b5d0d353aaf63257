// LAZ's integer "compressor", decoding side: a value is coded as its prediction plus a
// corrector. The corrector's magnitude class k (its bit length) is an adaptive symbol under
// one of several contexts; the corrector itself is a symbol of class k's model, its low bits
// raw beyond `bitsHigh` bits. Values wrap into the range of `bits` bits (or `range`).
#pragma once

#include "io/laz/arithmetic_decoder.hpp"

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

} // namespace omicron::laz
