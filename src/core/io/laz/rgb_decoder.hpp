// Colour in LAZ: red, green and blue are 16-bit, coded byte by byte as differences from the
// last colour. A mask says which bytes changed and whether the colour is grey (all channels
// equal red); green and blue are predicted from red's change, clamped to a byte. The RGB12
// item (version 2) codes this on the point-wise stream, RGB14 and RGBNIR14 (versions 3, 4) on
// their own layer, with one set of models per scanner channel.
#pragma once

#include "io/laz/arithmetic_decoder.hpp"
#include "io/laz/pointwise_item_decoder.hpp"

#include <array>
#include <cstdint>

namespace omicron::laz {

using Rgb = std::array<std::uint16_t, 3>;

struct RgbModels {
    SymbolModel changedBytes{128};
    // Per changed byte: red low, red high, green low, green high, blue low, blue high.
    std::array<SymbolModel, 6> byteDifference{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                              SymbolModel(256), SymbolModel(256), SymbolModel(256)};
};

// The colour after `last`.
Rgb decodeRgb(ArithmeticDecoder& decoder, RgbModels& models, const Rgb& last);

Rgb loadRgb(const std::uint8_t* bytes);
void storeRgb(std::uint8_t* bytes, const Rgb& rgb);

// The RGB12 item, version 2: three little-endian uint16.
class Rgb12Decoder final : public PointwiseItemDecoder {
public:
    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    RgbModels m_models;
    Rgb m_last{};
};

} // namespace omicron::laz
