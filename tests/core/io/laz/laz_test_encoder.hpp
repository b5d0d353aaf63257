// A LAZ encoder for tests: LASzip's arithmetic coder and integer compressor, writing side, over
// the decoder's own models (a symbol's probability is the same state on both sides), and the
// assembly of a LAZ file around encoded chunks. It makes the LAZ files no real file at hand
// gives: wave packets (point formats 4, 5, 9 and 10). Only what the tests need is encoded:
// every item the decoder knows is tested against real files made by other encoders.
#pragma once

#include "io/laz/arithmetic_model.hpp"
#include "io/laz/laszip_vlr.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace omicron::laz::test {

class ArithmeticEncoder {
public:
    void encodeBit(BitModel& model, std::uint32_t bit);
    void encodeSymbol(SymbolModel& model, std::uint32_t symbol);
    void writeBits(std::uint32_t bits, std::uint32_t value); // 1 to 32 bits
    void writeShort(std::uint32_t value);
    void writeInt64(std::uint64_t value); // low 32 bits first, each low 16 bits first
    // Flushes the interval (and the bytes the decoder reads ahead): the stream's bytes.
    std::vector<std::uint8_t> finish();

private:
    void propagateCarry();
    void renormalize();

    std::vector<std::uint8_t> m_bytes;
    std::uint32_t m_base = 0;
    std::uint32_t m_length = 0xFFFFFFFFu;
};

// The writing side of IntegerDecoder (same constructor arguments).
class IntegerEncoder {
public:
    explicit IntegerEncoder(std::uint32_t bits = 16, std::uint32_t contexts = 1,
                            std::uint32_t bitsHigh = 8);

    void encode(ArithmeticEncoder& encoder, std::int32_t prediction, std::int32_t value,
                std::uint32_t context = 0);
    std::uint32_t k() const { return m_k; }

private:
    std::uint32_t m_bitsHigh;
    std::uint32_t m_correctorBits;
    std::uint32_t m_correctorRange; // 0: all 32 bits
    std::int32_t m_correctorMin;
    std::int32_t m_correctorMax;
    std::uint32_t m_k = 0;
    std::vector<SymbolModel> m_classModels;
    BitModel m_corrector0;
    std::vector<std::unique_ptr<SymbolModel>> m_correctorModels;
};

// WAVEPACKET13 (and each channel's sequence of WAVEPACKET14): the item after `last`.
class WavePacketEncoder {
public:
    void encode(ArithmeticEncoder& encoder, const std::uint8_t* last, const std::uint8_t* item);

private:
    SymbolModel m_descriptorIndex{256};
    std::array<SymbolModel, 4> m_offsetKind{SymbolModel(4), SymbolModel(4), SymbolModel(4),
                                            SymbolModel(4)};
    IntegerEncoder m_offsetDifference{32};
    IntegerEncoder m_packetSize{32};
    IntegerEncoder m_returnPoint{32};
    IntegerEncoder m_step{32, 3};
    std::int32_t m_lastDifference = 0;
    std::uint32_t m_lastKind = 0;
};

// POINT10, GPSTIME11 and RGB12 (version 2) of a point equal to the chunk's first point but for
// its z (and an intensity of 0, which is what an unchanged intensity decodes to): only the
// coding of "unchanged" (and of z from the last z of its return level).
class UnchangedPointwiseEncoder {
public:
    // `recordFormat`: 4 (POINT10, GPSTIME11) or 5 (and RGB12); `first` the chunk's first record.
    UnchangedPointwiseEncoder(std::uint8_t recordFormat, const std::uint8_t* first);
    void encode(ArithmeticEncoder& encoder, std::int32_t z);

private:
    bool m_rgb;
    bool m_grey = false;
    std::uint32_t m_single;    // 1 for a single return: the coordinates' context
    std::int32_t m_lastZ = 0;  // the last z of the point's return level, 0 at first
    SymbolModel m_changed{64}; // POINT10's change mask
    IntegerEncoder m_dx{32, 2};
    IntegerEncoder m_dy{32, 22};
    IntegerEncoder m_z{32, 20};
    SymbolModel m_gpsZeroDifference{6};
    SymbolModel m_rgbChangedBytes{128};
};

// A LAZ file: `prefix` is the LAS header and the VLRs (`vlrCount`), the 'laszip encoded' record
// is appended, then the chunk table's offset, the chunks and the chunk table. The header's point
// format (compression bit set), record length, VLR count and point data offset are set.
struct LazAssembly {
    std::vector<std::uint8_t> prefix;
    std::uint32_t vlrCount = 0;
    std::uint8_t pointFormat = 0;
    std::uint16_t recordLength = 0;
    Compressor compressor = Compressor::PointwiseChunked;
    std::uint32_t chunkSize = 50000;
    std::vector<Item> items;
    std::vector<std::vector<std::uint8_t>> chunks;
};
std::vector<std::uint8_t> assembleLaz(const LazAssembly& laz);

} // namespace omicron::laz::test
