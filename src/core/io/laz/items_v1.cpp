#include "io/laz/items_v1.hpp"

#include "io/raw_bytes.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

static_assert(std::endian::native == std::endian::little, "LAS fields are stored with memcpy");

namespace omicron::laz {

namespace {

// Which fields changed, in the mask that follows a point's coordinates (version 2 swaps the
// first two).
constexpr unsigned kIntensityChanged = 1u << 5;
constexpr unsigned kReturnBitsChanged = 1u << 4;
constexpr unsigned kClassificationChanged = 1u << 3;
constexpr unsigned kScanAngleChanged = 1u << 2;
constexpr unsigned kUserDataChanged = 1u << 1;
constexpr unsigned kPointSourceChanged = 1u << 0;

// The true median of three (version 2's running median of five is an approximation).
std::int32_t median3(const std::array<std::int32_t, 3>& v) {
    return std::max(std::min(v[0], v[1]), std::min(std::max(v[0], v[1]), v[2]));
}

// The multiplier alphabet of GPSTIME11 v1: 0 to 509 multiply the last difference (0 means a
// quarter of it), 510 is a full new time, 511 the same time again.
constexpr std::uint32_t kMultiplierFull = 510;
constexpr std::uint32_t kMultiplierUnchanged = 511;
constexpr std::uint32_t kMultiplierLargest = 509;

} // namespace

SymbolModel& Point10V1Decoder::modelFor(ModelPerByte& models, std::uint8_t previous) {
    return lazyModel(models, previous, 256);
}

void Point10V1Decoder::start(const std::uint8_t* item) {
    std::copy_n(item, m_last.size(), m_last.begin()); // version 1 keeps the first intensity
}

void Point10V1Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    std::uint8_t* last = m_last.data();
    const std::int32_t dx = m_dx.decode(decoder, median3(m_xDiff));
    storeRaw(last, wrappingAdd(loadRaw<std::int32_t>(last), dx));
    const std::uint32_t kx = m_dx.k();
    const std::int32_t dy = m_dy.decode(decoder, median3(m_yDiff), std::min(kx, 19u));
    storeRaw(last + 4, wrappingAdd(loadRaw<std::int32_t>(last + 4), dy));
    const std::uint32_t k = (kx + m_dy.k()) / 2;
    storeRaw(last + 8, m_z.decode(decoder, loadRaw<std::int32_t>(last + 8), std::min(k, 19u)));

    const unsigned changed = decoder.decodeSymbol(m_changedValues);
    if (changed & kIntensityChanged) {
        storeRaw(last + 12, static_cast<std::uint16_t>(
                                m_intensity.decode(decoder, loadRaw<std::uint16_t>(last + 12))));
    }
    if (changed & kReturnBitsChanged) {
        last[14] =
            static_cast<std::uint8_t>(decoder.decodeSymbol(modelFor(m_returnBits, last[14])));
    }
    if (changed & kClassificationChanged) {
        last[15] =
            static_cast<std::uint8_t>(decoder.decodeSymbol(modelFor(m_classification, last[15])));
    }
    if (changed & kScanAngleChanged) {
        last[16] =
            static_cast<std::uint8_t>(m_scanAngleRank.decode(decoder, last[16], k < 3 ? 1u : 0u));
    }
    if (changed & kUserDataChanged) {
        last[17] = static_cast<std::uint8_t>(decoder.decodeSymbol(modelFor(m_userData, last[17])));
    }
    if (changed & kPointSourceChanged) {
        storeRaw(last + 18, static_cast<std::uint16_t>(m_pointSourceId.decode(
                                decoder, loadRaw<std::uint16_t>(last + 18))));
    }
    m_xDiff[m_next] = dx;
    m_yDiff[m_next] = dy;
    m_next = m_next == 2 ? 0 : m_next + 1;
    std::memcpy(item, last, m_last.size());
}

void GpsTime11V1Decoder::start(const std::uint8_t* item) {
    m_lastTime = loadRaw<std::uint64_t>(item);
}

void GpsTime11V1Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    // Differences are 32-bit and sign-extended onto the 64-bit pattern.
    const auto advance = [this](std::int32_t difference) {
        m_lastTime += static_cast<std::uint64_t>(static_cast<std::int64_t>(difference));
    };
    if (m_lastDifference == 0) {
        const std::uint32_t code = decoder.decodeSymbol(m_zeroDifference);
        if (code == 1) {
            m_lastDifference = m_integer.decode(decoder, 0, 0);
            advance(m_lastDifference);
        } else if (code == 2) {
            m_lastTime = decoder.readInt64();
        }
    } else {
        const std::uint32_t multiplier = decoder.decodeSymbol(m_multiplier);
        if (multiplier == kMultiplierFull) {
            m_lastTime = decoder.readInt64();
        } else if (multiplier != kMultiplierUnchanged) {
            std::int32_t difference;
            if (multiplier == 1) {
                difference = m_integer.decode(decoder, m_lastDifference, 1);
                m_lastDifference = difference;
                m_extremeCounter = 0;
            } else if (multiplier == 0) {
                difference = m_integer.decode(decoder, m_lastDifference / 4, 2);
                if (++m_extremeCounter > 3) {
                    m_lastDifference = difference;
                    m_extremeCounter = 0;
                }
            } else {
                // The encoder's 32-bit product wraps.
                const auto prediction = static_cast<std::int32_t>(
                    multiplier * static_cast<std::uint32_t>(m_lastDifference));
                const std::uint32_t context = multiplier < 10 ? 3 : multiplier < 50 ? 4 : 5;
                difference = m_integer.decode(decoder, prediction, context);
                if (multiplier == kMultiplierLargest && ++m_extremeCounter > 3) {
                    m_lastDifference = difference;
                    m_extremeCounter = 0;
                }
            }
            advance(difference);
        }
    }
    storeRaw(item, m_lastTime);
}

void Rgb12V1Decoder::start(const std::uint8_t* item) {
    std::copy_n(item, m_last.size(), m_last.begin());
}

void Rgb12V1Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    const std::uint32_t changed = decoder.decodeSymbol(m_changedBytes);
    for (std::uint32_t i = 0; i < m_last.size(); ++i) {
        if (changed & (1u << i)) {
            m_last[i] = static_cast<std::uint8_t>(m_byte.decode(decoder, m_last[i], i));
        }
    }
    std::memcpy(item, m_last.data(), m_last.size());
}

ByteV1Decoder::ByteV1Decoder(std::size_t byteCount)
    : m_last(byteCount), m_byte(8, static_cast<std::uint32_t>(byteCount)) {}

void ByteV1Decoder::start(const std::uint8_t* item) {
    std::copy_n(item, m_last.size(), m_last.begin());
}

void ByteV1Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    for (std::size_t i = 0; i < m_last.size(); ++i) {
        m_last[i] = static_cast<std::uint8_t>(
            m_byte.decode(decoder, m_last[i], static_cast<std::uint32_t>(i)));
        item[i] = m_last[i];
    }
}

} // namespace omicron::laz
