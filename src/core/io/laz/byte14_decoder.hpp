// The BYTE14 item, versions 3 and 4: a layered chunk's extra bytes, one layer per byte, each
// byte coded as the difference from the same byte of the last point. Carried through as raw
// bytes.
#pragma once

#include "io/laz/layered_item_decoder.hpp"

namespace omicron::laz {

class Byte14Decoder final : public LayeredItemDecoder {
public:
    Byte14Decoder(std::size_t byteCount, std::uint32_t version);

    std::size_t layerCount() const override { return m_byteCount; }
    void start(const std::uint8_t* firstItem, std::uint32_t channel,
               std::span<Layer> layers) override;
    void decode(std::uint8_t* item, std::uint32_t channel) override;

private:
    struct Models {
        explicit Models(std::size_t byteCount);
        std::vector<SymbolModel> byteDifference;
    };

    std::size_t m_byteCount;
    std::span<Layer> m_layers;
    ChannelContexts<Models> m_contexts;
};

} // namespace omicron::laz
