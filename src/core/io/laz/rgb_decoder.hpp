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
#include <cstring>

namespace omicron::laz {

using Rgb = std::array<std::uint16_t, 3>;

struct RgbModels {
    SymbolModel changedBytes{128};
    // Per changed byte: red low, red high, green low, green high, blue low, blue high.
    std::array<SymbolModel, 6> byteDifference{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                              SymbolModel(256), SymbolModel(256), SymbolModel(256)};
};

namespace rgb_detail {

inline std::uint32_t clampToByte(std::int32_t value) {
    return value <= 0 ? 0u : value >= 255 ? 255u : static_cast<std::uint32_t>(value);
}

// A byte coded as a difference from `predicted`, wrapping like the encoder's byte arithmetic.
inline std::uint16_t byteAfter(ArithmeticDecoder& decoder, SymbolModel& model,
                               std::uint32_t predicted) {
    return static_cast<std::uint16_t>((decoder.decodeSymbol(model) + predicted) & 0xFFu);
}

} // namespace rgb_detail

// The colour after `last`. Inline: a layer's loop keeps its decoder's state in registers.
inline Rgb decodeRgb(ArithmeticDecoder& decoder, RgbModels& models, const Rgb& last) {
    using rgb_detail::byteAfter;
    using rgb_detail::clampToByte;
    const std::uint32_t changed = decoder.decodeSymbol(models.changedBytes);
    const auto low = [](std::uint16_t v) {
        return static_cast<std::int32_t>(v & 0xFFu);
    };
    const auto high = [](std::uint16_t v) {
        return static_cast<std::int32_t>(v >> 8);
    };
    auto& difference = models.byteDifference;
    Rgb rgb;

    rgb[0] = (changed & 1u) ? byteAfter(decoder, difference[0], low(last[0]))
                            : static_cast<std::uint16_t>(low(last[0]));
    rgb[0] |= static_cast<std::uint16_t>(
        ((changed & 2u) ? byteAfter(decoder, difference[1], high(last[0])) : high(last[0])) << 8);

    if ((changed & (1u << 6)) == 0) { // grey: every channel as red
        rgb[1] = rgb[0];
        rgb[2] = rgb[0];
        return rgb;
    }
    // Low bytes: green follows red's change, blue the mean of red's and green's.
    std::int32_t change = low(rgb[0]) - low(last[0]);
    rgb[1] = (changed & 4u) ? byteAfter(decoder, difference[2], clampToByte(change + low(last[1])))
                            : static_cast<std::uint16_t>(low(last[1]));
    if (changed & 16u) {
        change = (change + low(rgb[1]) - low(last[1])) / 2;
        rgb[2] = byteAfter(decoder, difference[4], clampToByte(change + low(last[2])));
    } else {
        rgb[2] = static_cast<std::uint16_t>(low(last[2]));
    }
    // High bytes, the same way.
    change = high(rgb[0]) - high(last[0]);
    const std::uint32_t greenHigh =
        (changed & 8u) ? byteAfter(decoder, difference[3], clampToByte(change + high(last[1])))
                       : static_cast<std::uint32_t>(high(last[1]));
    rgb[1] |= static_cast<std::uint16_t>(greenHigh << 8);
    std::uint32_t blueHigh;
    if (changed & 32u) {
        change = (change + high(rgb[1]) - high(last[1])) / 2;
        blueHigh = byteAfter(decoder, difference[5], clampToByte(change + high(last[2])));
    } else {
        blueHigh = static_cast<std::uint32_t>(high(last[2]));
    }
    rgb[2] |= static_cast<std::uint16_t>(blueHigh << 8);
    return rgb;
}

// Inline: RGB14's layer loop calls them for every point.
inline Rgb loadRgb(const std::uint8_t* bytes) {
    Rgb rgb;
    std::memcpy(rgb.data(), bytes, sizeof rgb);
    return rgb;
}

inline void storeRgb(std::uint8_t* bytes, const Rgb& rgb) {
    std::memcpy(bytes, rgb.data(), sizeof rgb);
}

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
