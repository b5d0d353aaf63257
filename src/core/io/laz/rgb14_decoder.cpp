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
    const auto selected = m_contexts.select(channel);
    if (m_rgbLayer->present) {
        const Rgb rgb = decodeRgb(m_rgbLayer->decoder, selected.models.rgb, loadRgb(selected.last));
        storeRgb(selected.last, rgb);
    }
    std::memcpy(item, selected.last, 6);
    if (!m_withNir) {
        return;
    }
    if (m_nirLayer->present) {
        ArithmeticDecoder& decoder = m_nirLayer->decoder;
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
