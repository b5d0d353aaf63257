#include "laz_test_encoder.hpp"

#include "io/las/las_header.hpp"
#include "io/raw_bytes.hpp"

#include <cassert>
#include <cstring>
#include <limits>

namespace omicron::laz::test {

namespace {

constexpr std::uint32_t kMinLength = 0x01000000u;

template <typename T> void append(std::vector<std::uint8_t>& bytes, T value) {
    const std::size_t at = bytes.size();
    bytes.resize(at + sizeof value);
    std::memcpy(bytes.data() + at, &value, sizeof value);
}

template <typename T> void put(std::vector<std::uint8_t>& bytes, std::size_t at, T value) {
    std::memcpy(bytes.data() + at, &value, sizeof value);
}

} // namespace

void ArithmeticEncoder::encodeBit(BitModel& model, std::uint32_t bit) {
    const std::uint32_t bound = model.bit0Probability * (m_length >> kBitLengthShift);
    if (bit == 0) {
        m_length = bound;
        ++model.bit0Count;
    } else {
        const std::uint32_t before = m_base;
        m_base += bound;
        m_length -= bound;
        if (before > m_base) {
            propagateCarry();
        }
    }
    if (m_length < kMinLength) {
        renormalize();
    }
    if (--model.bitsUntilUpdate == 0) {
        model.update();
    }
}

void ArithmeticEncoder::encodeSymbol(SymbolModel& model, std::uint32_t symbol) {
    assert(symbol < model.symbols);
    const std::uint32_t before = m_base;
    if (symbol == model.lastSymbol) {
        const std::uint32_t lower = model.distribution[symbol] * (m_length >> kSymbolLengthShift);
        m_base += lower;
        m_length -= lower;
    } else {
        m_length >>= kSymbolLengthShift;
        const std::uint32_t lower = model.distribution[symbol] * m_length;
        m_base += lower;
        m_length = model.distribution[symbol + 1] * m_length - lower;
    }
    if (before > m_base) {
        propagateCarry();
    }
    if (m_length < kMinLength) {
        renormalize();
    }
    ++model.symbolCount[symbol];
    if (--model.symbolsUntilUpdate == 0) {
        model.update();
    }
}

void ArithmeticEncoder::writeBits(std::uint32_t bits, std::uint32_t value) {
    if (bits > 19) {
        writeShort(value & 0xFFFFu);
        value >>= 16;
        bits -= 16;
    }
    const std::uint32_t before = m_base;
    m_length >>= bits;
    m_base += value * m_length;
    if (before > m_base) {
        propagateCarry();
    }
    if (m_length < kMinLength) {
        renormalize();
    }
}

void ArithmeticEncoder::writeShort(std::uint32_t value) {
    writeBits(16, value);
}

void ArithmeticEncoder::writeInt64(std::uint64_t value) {
    for (int shift = 0; shift < 64; shift += 16) {
        writeShort(static_cast<std::uint32_t>(value >> shift) & 0xFFFFu);
    }
}

std::vector<std::uint8_t> ArithmeticEncoder::finish() {
    const std::uint32_t before = m_base;
    bool anotherByte = true;
    if (m_length > 2 * kMinLength) {
        m_base += kMinLength;
        m_length = kMinLength >> 1;
    } else {
        m_base += kMinLength >> 1;
        m_length = kMinLength >> 9;
        anotherByte = false;
    }
    if (before > m_base) {
        propagateCarry();
    }
    renormalize();
    // The decoder reads four bytes ahead of what it has decoded.
    m_bytes.insert(m_bytes.end(), anotherByte ? 3 : 2, 0);
    return std::move(m_bytes);
}

void ArithmeticEncoder::propagateCarry() {
    std::size_t at = m_bytes.size();
    while (at > 0 && m_bytes[at - 1] == 0xFF) {
        m_bytes[--at] = 0;
    }
    assert(at > 0);
    ++m_bytes[at - 1];
}

void ArithmeticEncoder::renormalize() {
    do {
        m_bytes.push_back(static_cast<std::uint8_t>(m_base >> 24));
        m_base <<= 8;
        m_length <<= 8;
    } while (m_length < kMinLength);
}

IntegerEncoder::IntegerEncoder(std::uint32_t bits, std::uint32_t contexts, std::uint32_t bitsHigh)
    : m_bitsHigh(bitsHigh) {
    if (bits < 32) {
        m_correctorBits = bits;
        m_correctorRange = std::uint32_t{1} << bits;
        m_correctorMin = -static_cast<std::int32_t>(m_correctorRange / 2);
        m_correctorMax = m_correctorMin + static_cast<std::int32_t>(m_correctorRange - 1);
    } else {
        m_correctorBits = 32;
        m_correctorRange = 0;
        m_correctorMin = std::numeric_limits<std::int32_t>::min();
        m_correctorMax = std::numeric_limits<std::int32_t>::max();
    }
    for (std::uint32_t i = 0; i < contexts; ++i) {
        m_classModels.emplace_back(m_correctorBits + 1);
    }
    m_correctorModels.resize(m_correctorBits + 1);
}

void IntegerEncoder::encode(ArithmeticEncoder& encoder, std::int32_t prediction, std::int32_t value,
                            std::uint32_t context) {
    auto corrector = static_cast<std::int32_t>(static_cast<std::uint32_t>(value) -
                                               static_cast<std::uint32_t>(prediction));
    if (corrector < m_correctorMin) {
        corrector += static_cast<std::int32_t>(m_correctorRange);
    } else if (corrector > m_correctorMax) {
        corrector -= static_cast<std::int32_t>(m_correctorRange);
    }
    // Class k holds the correctors of k bits: [-(2^k - 1), -2^(k-1)] and [2^(k-1) + 1, 2^k].
    std::uint32_t magnitude = corrector <= 0 ? static_cast<std::uint32_t>(-std::int64_t{corrector})
                                             : static_cast<std::uint32_t>(corrector - 1);
    m_k = 0;
    while (magnitude != 0) {
        magnitude >>= 1;
        ++m_k;
    }
    assert(m_k < 32 && "the tests need no corrector of 32 bits");
    encoder.encodeSymbol(m_classModels[context], m_k);
    if (m_k == 0) {
        encoder.encodeBit(m_corrector0, static_cast<std::uint32_t>(corrector));
        return;
    }
    auto coded = static_cast<std::uint32_t>(
        corrector < 0 ? corrector + static_cast<std::int32_t>((std::uint32_t{1} << m_k) - 1)
                      : corrector - 1);
    std::unique_ptr<SymbolModel>& model = m_correctorModels[m_k];
    if (!model) {
        model = std::make_unique<SymbolModel>(std::uint32_t{1}
                                              << (m_k <= m_bitsHigh ? m_k : m_bitsHigh));
    }
    if (m_k <= m_bitsHigh) {
        encoder.encodeSymbol(*model, coded);
        return;
    }
    const std::uint32_t rawBits = m_k - m_bitsHigh;
    encoder.encodeSymbol(*model, coded >> rawBits);
    encoder.writeBits(rawBits, coded & ((std::uint32_t{1} << rawBits) - 1));
}

void WavePacketEncoder::encode(ArithmeticEncoder& encoder, const std::uint8_t* last,
                               const std::uint8_t* item) {
    encoder.encodeSymbol(m_descriptorIndex, item[0]);
    const auto lastOffset = loadRaw<std::uint64_t>(last + 1);
    const auto offset = loadRaw<std::uint64_t>(item + 1);
    const auto lastSize = loadRaw<std::uint32_t>(last + 9);
    const auto difference = static_cast<std::int64_t>(offset - lastOffset);
    std::uint32_t kind = 3;
    if (difference == static_cast<std::int32_t>(difference)) {
        kind = difference == 0 ? 0 : difference == static_cast<std::int64_t>(lastSize) ? 1 : 2;
    }
    encoder.encodeSymbol(m_offsetKind[m_lastKind], kind);
    m_lastKind = kind;
    if (kind == 2) {
        m_offsetDifference.encode(encoder, m_lastDifference, static_cast<std::int32_t>(difference));
        m_lastDifference = static_cast<std::int32_t>(difference);
    } else if (kind == 3) {
        encoder.writeInt64(offset);
    }
    m_packetSize.encode(encoder, static_cast<std::int32_t>(lastSize),
                        loadRaw<std::int32_t>(item + 9));
    m_returnPoint.encode(encoder, loadRaw<std::int32_t>(last + 13),
                         loadRaw<std::int32_t>(item + 13));
    for (std::uint32_t axis = 0; axis < 3; ++axis) {
        m_step.encode(encoder, loadRaw<std::int32_t>(last + 17 + 4 * axis),
                      loadRaw<std::int32_t>(item + 17 + 4 * axis), axis);
    }
}

UnchangedPointwiseEncoder::UnchangedPointwiseEncoder(std::uint8_t recordFormat,
                                                     const std::uint8_t* first)
    : m_rgb(recordFormat == 5) {
    m_single = ((first[14] >> 3) & 7u) == 1 ? 1 : 0;
    if (m_rgb) { // RGB12 follows POINT10 and GPSTIME11
        const std::uint8_t* rgb = first + 28;
        m_grey = loadRaw<std::uint16_t>(rgb) == loadRaw<std::uint16_t>(rgb + 2) &&
                 loadRaw<std::uint16_t>(rgb) == loadRaw<std::uint16_t>(rgb + 4);
    }
}

void UnchangedPointwiseEncoder::encode(ArithmeticEncoder& encoder, std::int32_t z) {
    encoder.encodeSymbol(m_changed, 0);
    m_dx.encode(encoder, 0, 0, m_single); // the medians of the differences stay 0
    m_dy.encode(encoder, 0, 0, m_single); // k of x is 0
    m_z.encode(encoder, m_lastZ, z, m_single);
    m_lastZ = z;
    encoder.encodeSymbol(m_gpsZeroDifference, 0); // the same time again
    if (m_rgb) {
        encoder.encodeSymbol(m_rgbChangedBytes, m_grey ? 0 : 64); // no byte changed
    }
}

std::vector<std::uint8_t> assembleLaz(const LazAssembly& laz) {
    std::vector<std::uint8_t> payload;
    append<std::uint16_t>(payload, static_cast<std::uint16_t>(laz.compressor));
    append<std::uint16_t>(payload, 0); // arithmetic coder
    payload.push_back(3);              // LASzip 3.4r3
    payload.push_back(4);
    append<std::uint16_t>(payload, 3);
    append<std::uint32_t>(payload, 0);
    append<std::uint32_t>(payload, laz.chunkSize);
    append<std::int64_t>(payload, -1); // no special EVLRs
    append<std::int64_t>(payload, -1);
    append<std::uint16_t>(payload, static_cast<std::uint16_t>(laz.items.size()));
    for (const Item& item : laz.items) {
        append<std::uint16_t>(payload, static_cast<std::uint16_t>(item.type));
        append<std::uint16_t>(payload, item.size);
        append<std::uint16_t>(payload, item.version);
    }

    std::vector<std::uint8_t> file = laz.prefix;
    append<std::uint16_t>(file, 0);
    const char userId[16] = "laszip encoded";
    file.insert(file.end(), userId, userId + sizeof userId);
    append<std::uint16_t>(file, las::kLaszipRecordId);
    append<std::uint16_t>(file, static_cast<std::uint16_t>(payload.size()));
    file.insert(file.end(), 32, 0); // description
    file.insert(file.end(), payload.begin(), payload.end());

    const auto pointData = static_cast<std::uint32_t>(file.size());
    put<std::uint32_t>(file, las::field::pointDataOffset, pointData);
    put<std::uint32_t>(file, las::field::vlrCount, laz.vlrCount + 1);
    file[las::field::pointFormat] = static_cast<std::uint8_t>(laz.pointFormat | 0x80u);
    put<std::uint16_t>(file, las::field::recordLength, laz.recordLength);

    append<std::int64_t>(file, 0); // the chunk table's offset, set below
    for (const std::vector<std::uint8_t>& chunk : laz.chunks) {
        file.insert(file.end(), chunk.begin(), chunk.end());
    }
    put<std::int64_t>(file, pointData, static_cast<std::int64_t>(file.size()));
    append<std::uint32_t>(file, 0); // the table's version
    append<std::uint32_t>(file, static_cast<std::uint32_t>(laz.chunks.size()));
    ArithmeticEncoder encoder;
    IntegerEncoder numbers(32, 2);
    std::int32_t lastBytes = 0;
    for (const std::vector<std::uint8_t>& chunk : laz.chunks) {
        const auto bytes = static_cast<std::int32_t>(chunk.size());
        numbers.encode(encoder, lastBytes, bytes, 1);
        lastBytes = bytes;
    }
    const std::vector<std::uint8_t> table = encoder.finish();
    file.insert(file.end(), table.begin(), table.end());
    return file;
}

} // namespace omicron::laz::test
