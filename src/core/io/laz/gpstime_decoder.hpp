// GPS times in LAZ: the 64-bit pattern of the double, predicted in up to four interleaved
// sequences (pulses of several scanners or flight lines). A time is coded as a multiple of its
// sequence's last 32-bit difference plus a corrector, as a full new value that starts another
// sequence, or as a switch to one of the other sequences.
//
// The GPSTIME11 item (version 2, point formats 1, 3, 4, 5) and the GPS time layer of the POINT14
// item (version 3 and 4) use the same scheme; POINT14 says in its own change mask whether the
// time changed, so its symbol alphabet lacks the "unchanged" codes.
#pragma once

#include "io/laz/integer_decoder.hpp"
#include "io/laz/pointwise_item_decoder.hpp"

#include <array>
#include <cstdint>

namespace omicron::laz {

class GpsTimeDecoder {
public:
    enum class Alphabet {
        WithUnchanged, // GPSTIME11 v2
        ChangedOnly,   // POINT14 v3/v4: only called when the time changed
    };

    GpsTimeDecoder(Alphabet alphabet, std::uint64_t firstTimeBits);

    // The next time's bits. The decoded sequence switches are bounded: a corrupt stream that
    // keeps switching gets a value, never a loop.
    std::uint64_t decode(ArithmeticDecoder& decoder);

private:
    std::int32_t decodeDifference(ArithmeticDecoder& decoder, std::uint32_t multiplier);
    void startSequence(ArithmeticDecoder& decoder);

    std::uint32_t m_unchangedCodes; // 1 for WithUnchanged, 0 otherwise
    std::uint32_t m_codeFull;       // the "full new value" code of the multiplier alphabet
    SymbolModel m_multiplier;
    SymbolModel m_zeroDifference; // used while the last difference is 0
    IntegerDecoder m_integer{32, 9};
    std::uint32_t m_last = 0; // the sequence of the last time
    std::uint32_t m_next = 0; // the sequence a full value replaces
    std::array<std::uint64_t, 4> m_lastTime{};
    std::array<std::int32_t, 4> m_lastDifference{};
    std::array<std::int32_t, 4> m_extremeCounter{};
};

// The GPSTIME11 item, version 2: an 8-byte double.
class GpsTime11Decoder final : public PointwiseItemDecoder {
public:
    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    GpsTimeDecoder m_times{GpsTimeDecoder::Alphabet::WithUnchanged, 0};
};

} // namespace omicron::laz
