#include "io/laz/gpstime_decoder.hpp"

#include <cstring>

namespace omicron::laz {

namespace {

// The multiplier alphabet: codes below 500 are multiples of the last difference, 500 the
// largest, 501..510 the negative multiples -1..-10.
constexpr std::int32_t kMultiMax = 500;
constexpr std::int32_t kMultiMin = -10;
constexpr std::uint32_t kMultiCodes = kMultiMax - kMultiMin + 1; // 511: the codes above

// A valid stream switches sequence at most once per time; more is corrupt data, which then
// decodes to some value instead of looping.
constexpr int kMaxSwitches = 4;

std::int32_t times(std::int32_t multiplier, std::int32_t difference) {
    // Wraps like the encoder's 32-bit product.
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(multiplier) *
                                     static_cast<std::uint32_t>(difference));
}

} // namespace

GpsTimeDecoder::GpsTimeDecoder(Alphabet alphabet, std::uint64_t firstTimeBits)
    : m_unchangedCodes(alphabet == Alphabet::WithUnchanged ? 1 : 0),
      m_codeFull(kMultiCodes + m_unchangedCodes), m_multiplier(m_codeFull + 4),
      m_zeroDifference(5 + m_unchangedCodes) {
    m_lastTime[0] = firstTimeBits;
}

void GpsTimeDecoder::startSequence(ArithmeticDecoder& decoder) {
    m_next = (m_next + 1) & 3;
    const auto highPrediction = static_cast<std::int32_t>(m_lastTime[m_last] >> 32);
    const auto high = static_cast<std::uint32_t>(m_integer.decode(decoder, highPrediction, 8));
    m_lastTime[m_next] = (std::uint64_t{high} << 32) | decoder.readInt();
    m_last = m_next;
    m_lastDifference[m_last] = 0;
    m_extremeCounter[m_last] = 0;
}

// Codes 0 and 2..510 of the multiplier alphabet: a difference predicted from a multiple of the
// last one. Multipliers far from 1 (0, 500, -10) replace the last difference only after they
// occur more than three times in a row.
std::int32_t GpsTimeDecoder::decodeDifference(ArithmeticDecoder& decoder,
                                              std::uint32_t multiplier) {
    std::int32_t& lastDifference = m_lastDifference[m_last];
    std::int32_t& extremes = m_extremeCounter[m_last];
    std::int32_t difference;
    bool extreme = false;
    if (multiplier == 0) {
        difference = m_integer.decode(decoder, 0, 7);
        extreme = true;
    } else if (multiplier < static_cast<std::uint32_t>(kMultiMax)) {
        const auto factor = static_cast<std::int32_t>(multiplier);
        difference =
            m_integer.decode(decoder, times(factor, lastDifference), multiplier < 10 ? 2 : 3);
    } else if (multiplier == static_cast<std::uint32_t>(kMultiMax)) {
        difference = m_integer.decode(decoder, times(kMultiMax, lastDifference), 4);
        extreme = true;
    } else {
        const std::int32_t factor = kMultiMax - static_cast<std::int32_t>(multiplier);
        if (factor > kMultiMin) {
            difference = m_integer.decode(decoder, times(factor, lastDifference), 5);
        } else {
            difference = m_integer.decode(decoder, times(kMultiMin, lastDifference), 6);
            extreme = true;
        }
    }
    if (extreme && ++extremes > 3) {
        lastDifference = difference;
        extremes = 0;
    }
    return difference;
}

std::uint64_t GpsTimeDecoder::decode(ArithmeticDecoder& decoder) {
    for (int switches = 0; switches <= kMaxSwitches; ++switches) {
        if (m_lastDifference[m_last] == 0) {
            const std::uint32_t code = decoder.decodeSymbol(m_zeroDifference);
            if (code < m_unchangedCodes) {
                break; // the same time again
            }
            const std::uint32_t kind = code - m_unchangedCodes;
            if (kind == 0) { // a difference that fits 32 bits
                const std::int32_t difference = m_integer.decode(decoder, 0, 0);
                m_lastDifference[m_last] = difference;
                m_lastTime[m_last] += static_cast<std::uint64_t>(std::int64_t{difference});
                m_extremeCounter[m_last] = 0;
            } else if (kind == 1) {
                startSequence(decoder);
            } else {
                m_last = (m_last + kind - 1) & 3;
                continue;
            }
            break;
        }
        const std::uint32_t code = decoder.decodeSymbol(m_multiplier);
        if (code == 1) { // the last difference again, corrected
            const std::int32_t difference = m_integer.decode(decoder, m_lastDifference[m_last], 1);
            m_lastTime[m_last] += static_cast<std::uint64_t>(std::int64_t{difference});
            m_extremeCounter[m_last] = 0;
        } else if (code < kMultiCodes) {
            const std::int32_t difference = decodeDifference(decoder, code);
            m_lastTime[m_last] += static_cast<std::uint64_t>(std::int64_t{difference});
        } else if (code < m_codeFull) {
            // GPSTIME11's "unchanged" code
        } else if (code == m_codeFull) {
            startSequence(decoder);
        } else {
            m_last = (m_last + code - m_codeFull) & 3;
            continue;
        }
        break;
    }
    return m_lastTime[m_last];
}

void GpsTime11Decoder::start(const std::uint8_t* item) {
    std::uint64_t bits;
    std::memcpy(&bits, item, sizeof bits);
    m_times = GpsTimeDecoder(GpsTimeDecoder::Alphabet::WithUnchanged, bits);
}

void GpsTime11Decoder::decode(ArithmeticDecoder& decoder, std::uint8_t* item) {
    const std::uint64_t bits = m_times.decode(decoder);
    std::memcpy(item, &bits, sizeof bits);
}

} // namespace omicron::laz
