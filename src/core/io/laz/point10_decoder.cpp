#include "io/laz/point10_decoder.hpp"

#include "io/laz/return_contexts.hpp"
#include "io/raw_bytes.hpp"

#include <bit>
#include <cstring>

static_assert(std::endian::native == std::endian::little, "LAS fields are stored with memcpy");

namespace omicron::laz {

namespace {

// Which fields changed, in the bit mask each point starts with.
constexpr unsigned kReturnBitsChanged = 1u << 5;
constexpr unsigned kIntensityChanged = 1u << 4;
constexpr unsigned kClassificationChanged = 1u << 3;
constexpr unsigned kScanAngleChanged = 1u << 2;
constexpr unsigned kUserDataChanged = 1u << 1;
constexpr unsigned kPointSourceChanged = 1u << 0;

// The even part of k, at most `limit`: how a coordinate's magnitude class selects the next
// coordinate's context.
std::uint32_t evenClass(std::uint32_t k, std::uint32_t limit) {
    return k < limit ? (k & ~1u) : limit;
}

} // namespace

Point10Decoder::Point10Decoder() = default;

SymbolModel& Point10Decoder::modelFor(ModelPerByte& models, std::uint8_t previous) {
    return lazyModel(models, previous, 256);
}

void Point10Decoder::start(const std::uint8_t* item) {
    m_last.x = loadRaw<std::int32_t>(item);
    m_last.y = loadRaw<std::int32_t>(item + 4);
    m_last.z = loadRaw<std::int32_t>(item + 8);
    // The first intensity is not a prediction: LASzip starts from 0 in every context.
    m_last.intensity = 0;
    m_last.returnBits = item[14];
    m_last.classification = item[15];
    m_last.scanAngleRank = item[16];
    m_last.userData = item[17];
    m_last.pointSourceId = loadRaw<std::uint16_t>(item + 18);
}

void Point10Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    const unsigned changed = decoder.decodeSymbol(m_changedValues);
    if (changed & kReturnBitsChanged) {
        m_last.returnBits = static_cast<std::uint8_t>(
            decoder.decodeSymbol(modelFor(m_returnBits, m_last.returnBits)));
    }
    const std::uint32_t returnNumber = m_last.returnBits & 7u;
    const std::uint32_t numberOfReturns = (m_last.returnBits >> 3) & 7u;
    const std::uint32_t map = returnMap8(numberOfReturns, returnNumber);
    const std::uint32_t level = returnLevel8(numberOfReturns, returnNumber);

    if (changed & kIntensityChanged) {
        m_last.intensity = static_cast<std::uint16_t>(
            m_intensity.decode(decoder, m_lastIntensity[map], map < 3 ? map : 3));
        m_lastIntensity[map] = m_last.intensity;
    } else {
        m_last.intensity = m_lastIntensity[map];
    }
    if (changed & kClassificationChanged) {
        m_last.classification = static_cast<std::uint8_t>(
            decoder.decodeSymbol(modelFor(m_classification, m_last.classification)));
    }
    if (changed & kScanAngleChanged) {
        const unsigned scanDirection = (m_last.returnBits >> 6) & 1u;
        const std::uint32_t delta = decoder.decodeSymbol(m_scanAngleRank[scanDirection]);
        m_last.scanAngleRank = static_cast<std::uint8_t>(delta + m_last.scanAngleRank);
    }
    if (changed & kUserDataChanged) {
        m_last.userData =
            static_cast<std::uint8_t>(decoder.decodeSymbol(modelFor(m_userData, m_last.userData)));
    }
    if (changed & kPointSourceChanged) {
        m_last.pointSourceId =
            static_cast<std::uint16_t>(m_pointSourceId.decode(decoder, m_last.pointSourceId));
    }

    const std::uint32_t single = numberOfReturns == 1 ? 1 : 0;
    const std::int32_t dx = m_dx.decode(decoder, m_xDiffMedian[map].median(), single);
    m_last.x = wrappingAdd(m_last.x, dx);
    m_xDiffMedian[map].add(dx);

    const std::int32_t dy =
        m_dy.decode(decoder, m_yDiffMedian[map].median(), single + evenClass(m_dx.k(), 20));
    m_last.y = wrappingAdd(m_last.y, dy);
    m_yDiffMedian[map].add(dy);

    const std::uint32_t zClass = (m_dx.k() + m_dy.k()) / 2;
    m_last.z = m_z.decode(decoder, m_lastHeight[level], single + evenClass(zClass, 18));
    m_lastHeight[level] = m_last.z;

    storeRaw(item, m_last.x);
    storeRaw(item + 4, m_last.y);
    storeRaw(item + 8, m_last.z);
    storeRaw(item + 12, m_last.intensity);
    item[14] = m_last.returnBits;
    item[15] = m_last.classification;
    item[16] = m_last.scanAngleRank;
    item[17] = m_last.userData;
    storeRaw(item + 18, m_last.pointSourceId);
}

} // namespace omicron::laz
