#include "io/laz/rgb14_decoder.hpp"

#include <cassert>
#include <cstring>

namespace omicron::laz {

Rgb14Decoder::Rgb14Decoder(bool withNir, std::uint32_t version)
    : m_withNir(withNir), m_contexts(withNir ? 8 : 6, version) {}

void Rgb14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                         std::span<Layer> layers) {
    assert(layers.size() == layerCount());
    m_rgbLayer = &layers[0];
    m_nirLayer = m_withNir ? &layers[1] : nullptr;
    m_contexts.start(firstItem, channel);
}

void Rgb14Decoder::decode(std::uint8_t* item, std::uint32_t channel) {
    ArithmeticDecoder unused;
    decodeOne(item, channel, m_rgbLayer->decoder, m_nirLayer ? m_nirLayer->decoder : unused);
}

void Rgb14Decoder::decode(std::uint8_t* items, std::size_t count, std::size_t stride,
                          const std::uint8_t* channels) {
    // Copies in locals, put back after the loop: their state stays in registers.
    ArithmeticDecoder rgb = m_rgbLayer->decoder;
    ArithmeticDecoder nir = m_nirLayer ? m_nirLayer->decoder : ArithmeticDecoder();
    for (std::size_t i = 0; i < count; ++i) {
        decodeOne(items + i * stride, channels[i], rgb, nir);
    }
    m_rgbLayer->decoder = rgb;
    if (m_nirLayer) {
        m_nirLayer->decoder = nir;
    }
}

inline void Rgb14Decoder::decodeOne(std::uint8_t* item, std::uint32_t channel,
                                    ArithmeticDecoder& rgbDecoder, ArithmeticDecoder& nirDecoder) {
    const auto selected = m_contexts.select(channel);
    if (m_rgbLayer->present) {
        const Rgb rgb = decodeRgb(rgbDecoder, selected.models.rgb, loadRgb(selected.last));
        storeRgb(selected.last, rgb);
    }
    std::memcpy(item, selected.last, 6);
    if (!m_withNir) {
        return;
    }
    if (m_nirLayer->present) {
        ArithmeticDecoder& decoder = nirDecoder;
        Models& models = selected.models;
        std::uint16_t last;
        std::memcpy(&last, selected.last + 6, sizeof last);
        const std::uint32_t changed = decoder.decodeSymbol(models.nirChangedBytes);
        std::uint32_t low = last & 0xFFu;
        std::uint32_t high = last >> 8;
        if (changed & 1u) {
            low = (decoder.decodeSymbol(models.nirByteDifference[0]) + low) & 0xFFu;
        }
        if (changed & 2u) {
            high = (decoder.decodeSymbol(models.nirByteDifference[1]) + high) & 0xFFu;
        }
        const auto nir = static_cast<std::uint16_t>(low | (high << 8));
        std::memcpy(selected.last + 6, &nir, sizeof nir);
    }
    std::memcpy(item + 6, selected.last + 6, 2);
}

} // namespace omicron::laz
