// The BYTE item, version 2: a point-wise chunk's extra bytes, each byte coded as the
// difference from the same byte of the last point under its own model. Carried through as raw
// bytes: what they mean is the extra-bytes VLR's business.
#pragma once

#include "io/laz/pointwise_item_decoder.hpp"

#include <cstddef>
#include <vector>

namespace omicron::laz {

class ByteDecoder final : public PointwiseItemDecoder {
public:
    explicit ByteDecoder(std::size_t byteCount);

    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    std::vector<SymbolModel> m_models;
    std::vector<std::uint8_t> m_last;
};

} // namespace omicron::laz
