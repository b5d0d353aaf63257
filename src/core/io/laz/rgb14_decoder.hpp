// The RGB14 item (colour, one layer) and the RGBNIR14 item (colour and near infrared, two
// layers), versions 3 and 4. Colour is coded as for RGB12 (rgb_decoder.hpp); NIR's two bytes
// as differences from the last NIR.
#pragma once

#include "io/laz/layered_item_decoder.hpp"
#include "io/laz/rgb_decoder.hpp"

namespace omicron::laz {

class Rgb14Decoder final : public LayeredItemDecoder {
public:
    // `withNir`: the RGBNIR14 item (8 bytes) rather than RGB14 (6 bytes).
    Rgb14Decoder(bool withNir, std::uint32_t version);

    std::size_t layerCount() const override { return m_withNir ? 2 : 1; }
    void start(const std::uint8_t* firstItem, std::uint32_t channel,
               std::span<Layer> layers) override;
    void decode(std::uint8_t* item, std::uint32_t channel) override;
    void decode(std::uint8_t* items, std::size_t count, std::size_t stride,
                const std::uint8_t* channels) override;

private:
    struct Models {
        explicit Models(std::size_t /*itemBytes*/) {}
        RgbModels rgb;
        SymbolModel nirChangedBytes{4};
        std::array<SymbolModel, 2> nirByteDifference{SymbolModel(256), SymbolModel(256)};
    };

    void decodeOne(std::uint8_t* item, std::uint32_t channel, ArithmeticDecoder& rgb,
                   ArithmeticDecoder& nir);

    bool m_withNir;
    Layer* m_rgbLayer = nullptr;
    Layer* m_nirLayer = nullptr;
    ChannelContexts<Models> m_contexts;
};

} // namespace omicron::laz
