#include "io/laz/byte14_decoder.hpp"

#include <cassert>

namespace omicron::laz {

Byte14Decoder::Models::Models(std::size_t byteCount) {
    byteDifference.reserve(byteCount);
    for (std::size_t i = 0; i < byteCount; ++i) {
        byteDifference.emplace_back(256);
    }
}

Byte14Decoder::Byte14Decoder(std::size_t byteCount, std::uint32_t version)
    : m_byteCount(byteCount), m_contexts(byteCount, version) {}

void Byte14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                          std::span<Layer> layers) {
    assert(layers.size() == m_byteCount);
    m_layers = layers;
    m_contexts.start(firstItem, channel);
}

void Byte14Decoder::decode(std::uint8_t* item, std::uint32_t channel) {
    const auto selected = m_contexts.select(channel);
    for (std::size_t i = 0; i < m_byteCount; ++i) {
        Layer& layer = m_layers[i];
        if (layer.present) {
            const std::uint32_t difference =
                layer.decoder.decodeSymbol(selected.models.byteDifference[i]);
            selected.last[i] = static_cast<std::uint8_t>(selected.last[i] + difference);
        }
        item[i] = selected.last[i];
    }
}

} // namespace omicron::laz
