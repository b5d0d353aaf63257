// LAZ's arithmetic decoder (LASzip's, after Amir Said's FastAC: 32-bit interval, byte-wise
// renormalisation) over one span of compressed bytes: a point-wise chunk, or one layer of a
// layered chunk.
//
// Untrusted bytes never make it read outside its span or divide by zero: past the end it
// shifts in zeros and counts the bytes it lacked (overran() tells the caller that the data
// was truncated or corrupt), and a corrupt state only yields wrong symbols. A well-formed
// stream is consumed exactly: the encoder flushes the bytes the decoder will look ahead.
#pragma once

#include "io/laz/arithmetic_model.hpp"

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace omicron::laz {

class ArithmeticDecoder {
public:
    // A decoder over no bytes: any use overruns (an empty layer that should not be read).
    ArithmeticDecoder() = default;

    // Starts decoding [begin, end); reads the first four bytes into the interval's value.
    void start(const std::uint8_t* begin, const std::uint8_t* end);

    std::uint32_t decodeBit(BitModel& model) {
        const std::uint32_t bound = model.bit0Probability * (m_length >> kBitLengthShift);
        std::uint32_t bit;
        if (m_value < bound) {
            bit = 0;
            m_length = bound;
            ++model.bit0Count;
        } else {
            bit = 1;
            m_value -= bound;
            m_length -= bound;
        }
        keepLength();
        if (--model.bitsUntilUpdate == 0) {
            model.update();
        }
        return bit;
    }

    std::uint32_t decodeSymbol(SymbolModel& model) {
        std::uint32_t symbol;
        std::uint32_t lower;
        std::uint32_t upper = m_length;
        if (model.tableSize != 0) {
            m_length >>= kSymbolLengthShift;
            const std::uint32_t scaled = m_value / m_length;
            std::uint32_t slot = scaled >> model.tableShift;
            // Only a corrupt stream (value >= length) reaches past the table.
            if (slot > model.tableSize) {
                slot = model.tableSize;
            }
            symbol = model.decoderTable[slot];
            std::uint32_t end = model.decoderTable[slot + 1] + 1;
            while (end > symbol + 1) { // bisection between the table's bounds
                const std::uint32_t middle = (symbol + end) >> 1;
                if (model.distribution[middle] > scaled) {
                    end = middle;
                } else {
                    symbol = middle;
                }
            }
            lower = model.distribution[symbol] * m_length;
            if (symbol != model.lastSymbol) {
                upper = model.distribution[symbol + 1] * m_length;
            }
        } else {
            lower = 0;
            symbol = 0;
            m_length >>= kSymbolLengthShift;
            std::uint32_t end = model.symbols;
            std::uint32_t middle = end >> 1;
            do { // bisection over the products, no division
                const std::uint32_t product = m_length * model.distribution[middle];
                if (product > m_value) {
                    end = middle;
                    upper = product;
                } else {
                    symbol = middle;
                    lower = product;
                }
                middle = (symbol + end) >> 1;
            } while (middle != symbol);
        }
        m_value -= lower;
        m_length = upper - lower;
        keepLength();
        ++model.symbolCount[symbol];
        if (--model.symbolsUntilUpdate == 0) {
            model.update();
        }
        return symbol;
    }

    // `bits` raw (equiprobable) bits, 1 to 32.
    std::uint32_t readBits(std::uint32_t bits) {
        if (bits > 19) { // the interval holds at most 19 more bits at once
            const std::uint32_t low = readShort();
            return (readBits(bits - 16) << 16) | low;
        }
        m_length >>= bits;
        const std::uint32_t value = m_value / m_length;
        m_value -= m_length * value;
        keepLength();
        return value;
    }

    std::uint32_t readShort() {
        m_length >>= 16;
        const std::uint32_t value = m_value / m_length;
        m_value -= m_length * value;
        keepLength();
        return value;
    }

    // Low 16 bits first.
    std::uint32_t readInt() {
        const std::uint32_t low = readShort();
        const std::uint32_t high = readShort();
        return (high << 16) | low;
    }

    // Low 32 bits first (GPSTIME11 version 1's full times).
    std::uint64_t readInt64() {
        const std::uint64_t low = readInt();
        const std::uint64_t high = readInt();
        return (high << 32) | low;
    }

    // True when decoding needed bytes past the end of its span.
    bool overran() const { return m_missingBytes != 0; }
    // Bytes of the span consumed so far (at most its size).
    std::size_t consumed() const { return static_cast<std::size_t>(m_next - m_begin); }

private:
    static constexpr std::uint32_t kMinLength = 0x01000000u;
    static constexpr std::uint32_t kMaxLength = 0xFFFFFFFFu;

    std::uint32_t nextByte() {
        if (m_next != m_end) {
            return *m_next++;
        }
        ++m_missingBytes;
        return 0;
    }

    // Keeps the interval length at 2^24 or more, so every product above keeps its precision.
    // Shifts in the 0 to 3 bytes that takes without a branch on whether it is needed (which
    // the data decides, so it was often mispredicted), except in the span's last 4 bytes.
    void keepLength() {
        if (m_end - m_next >= 4) [[likely]] {
            // A length never reaches 0 (every symbol keeps at least 2^9 of it); the mask keeps
            // the shifts defined even so.
            const unsigned bits = static_cast<unsigned>(std::countl_zero(m_length)) & 24u;
            std::uint32_t ahead;
            std::memcpy(&ahead, m_next, sizeof ahead);
            ahead = __builtin_bswap32(ahead);
            const auto in = static_cast<std::uint32_t>((std::uint64_t{ahead} << bits) >> 32);
            m_value = static_cast<std::uint32_t>((std::uint64_t{m_value} << bits) | in);
            m_length <<= bits;
            m_next += bits >> 3;
        } else if (m_length < kMinLength) {
            renormalize();
        }
    }

    // keepLength's loop for a span's last bytes (nextByte counts those it lacks).
    void renormalize() {
        do {
            m_value = (m_value << 8) | nextByte();
            m_length <<= 8;
        } while (m_length < kMinLength);
    }

    const std::uint8_t* m_begin = nullptr;
    const std::uint8_t* m_next = nullptr;
    const std::uint8_t* m_end = nullptr;
    std::uint64_t m_missingBytes = 0;
    std::uint32_t m_value = 0;
    std::uint32_t m_length = kMaxLength;
};

} // namespace omicron::laz
