// The wave packet items of the waveform point formats: WAVEPACKET13 (formats 4 and 5,
// point-wise; LASzip codes it only as version 1, in version 2 files too) and WAVEPACKET14
// (formats 9 and 10, one layer, versions 3 and 4). An item is the 29 bytes that locate a
// point's waveform: descriptor index, byte offset and size of the packet, return point and the
// x/y/z step. omicron ignores waveforms, but decodes the items all the same: point-wise they
// share the arithmetic stream with the point's other items, and the records it hands on are
// then the file's records, byte for byte.
#pragma once

#include "io/laz/integer_decoder.hpp"
#include "io/laz/layered_item_decoder.hpp"
#include "io/laz/pointwise_item_decoder.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace omicron::laz {

inline constexpr std::size_t kWavePacketBytes = 29;

// The models and state of one wave packet sequence (one per chunk point-wise, one per scanner
// channel layered).
struct WavePacketModels {
    explicit WavePacketModels(std::size_t /*itemBytes*/ = kWavePacketBytes) {}

    SymbolModel descriptorIndex{256};
    // How the offset follows the last packet's (0 same, 1 right after it, 2 a 32-bit
    // difference, 3 a full 64-bit offset), in a context of the last such choice.
    std::array<SymbolModel, 4> offsetKind{SymbolModel(4), SymbolModel(4), SymbolModel(4),
                                          SymbolModel(4)};
    IntegerDecoder offsetDifference{32};
    IntegerDecoder packetSize{32};
    IntegerDecoder returnPoint{32};
    IntegerDecoder step{32, 3}; // x, y and z, a context each
    std::int32_t lastDifference = 0;
    std::uint32_t lastKind = 0;
};

// Decodes the item after `last` into `item` (29 bytes each, distinct).
void decodeWavePacket(ArithmeticDecoder& decoder, WavePacketModels& models,
                      const std::uint8_t* last, std::uint8_t* item);

class WavePacket13Decoder final : public PointwiseItemDecoder {
public:
    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    std::array<std::uint8_t, kWavePacketBytes> m_last{};
    WavePacketModels m_models;
};

class WavePacket14Decoder final : public LayeredItemDecoder {
public:
    explicit WavePacket14Decoder(std::uint32_t version);

    std::size_t layerCount() const override { return 1; }
    void start(const std::uint8_t* firstItem, std::uint32_t channel,
               std::span<Layer> layers) override;
    void decode(std::uint8_t* item, std::uint32_t channel) override;

private:
    Layer* m_layer = nullptr;
    ChannelContexts<WavePacketModels> m_contexts;
};

} // namespace omicron::laz
