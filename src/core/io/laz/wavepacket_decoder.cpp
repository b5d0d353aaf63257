#include "io/laz/wavepacket_decoder.hpp"

#include "io/raw_bytes.hpp"

#include <bit>
#include <cassert>
#include <cstring>

static_assert(std::endian::native == std::endian::little, "LAS fields are stored with memcpy");

namespace omicron::laz {

namespace {

// Where the fields lie in the item.
constexpr std::size_t kOffsetAt = 1;       // u64
constexpr std::size_t kSizeAt = 9;         // u32
constexpr std::size_t kReturnPointAt = 13; // f32, coded as its bits
constexpr std::size_t kStepAt = 17;        // f32[3], likewise

// The next value of a 32-bit field (an integer or a float's bits) predicted by its last value.
void decodeField(ArithmeticDecoder& decoder, IntegerDecoder& integer, const std::uint8_t* last,
                 std::uint8_t* item, std::size_t at, std::uint32_t context = 0) {
    storeRaw(item + at, integer.decode(decoder, loadRaw<std::int32_t>(last + at), context));
}

} // namespace

void decodeWavePacket(ArithmeticDecoder& decoder, WavePacketModels& models,
                      const std::uint8_t* last, std::uint8_t* item) {
    item[0] = static_cast<std::uint8_t>(decoder.decodeSymbol(models.descriptorIndex));
    models.lastKind = decoder.decodeSymbol(models.offsetKind[models.lastKind]);
    const auto lastOffset = loadRaw<std::uint64_t>(last + kOffsetAt);
    std::uint64_t offset;
    switch (models.lastKind) {
    case 0:
        offset = lastOffset;
        break;
    case 1:
        offset = lastOffset + loadRaw<std::uint32_t>(last + kSizeAt);
        break;
    case 2:
        models.lastDifference = models.offsetDifference.decode(decoder, models.lastDifference);
        // The signed difference, added modulo 2^64 as the encoder subtracted.
        offset = lastOffset + static_cast<std::uint64_t>(std::int64_t{models.lastDifference});
        break;
    default:
        offset = decoder.readInt64();
        break;
    }
    storeRaw(item + kOffsetAt, offset);
    decodeField(decoder, models.packetSize, last, item, kSizeAt);
    decodeField(decoder, models.returnPoint, last, item, kReturnPointAt);
    for (std::uint32_t axis = 0; axis < 3; ++axis) {
        decodeField(decoder, models.step, last, item, kStepAt + 4 * axis, axis);
    }
}

void WavePacket13Decoder::start(const std::uint8_t* item) {
    std::memcpy(m_last.data(), item, kWavePacketBytes);
}

void WavePacket13Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    decodeWavePacket(decoder, m_models, m_last.data(), item);
    std::memcpy(m_last.data(), item, kWavePacketBytes);
}

WavePacket14Decoder::WavePacket14Decoder(std::uint32_t version)
    : m_contexts(kWavePacketBytes, version) {}

void WavePacket14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                                std::span<Layer> layers) {
    assert(layers.size() == layerCount());
    m_layer = &layers[0];
    m_contexts.start(firstItem, channel);
}

void WavePacket14Decoder::decode(std::uint8_t* item, std::uint32_t channel) {
    const auto selected = m_contexts.select(channel);
    if (m_layer->present) { // an empty layer: every packet as the chunk's first
        decodeWavePacket(m_layer->decoder, selected.models, selected.last, item);
        std::memcpy(selected.last, item, kWavePacketBytes);
    } else {
        std::memcpy(item, selected.last, kWavePacketBytes);
    }
}

} // namespace omicron::laz
