#include "io/laz/laszip_vlr.hpp"

#include "io/input_error.hpp"

#include <cstring>

namespace omicron::laz {

namespace {

// Payload layout: compressor u16, coder u16, version u8 u8 u16, options u32, chunk size u32,
// special EVLR count i64 and offset i64 (unused), item count u16, then 6 bytes an item.
constexpr std::size_t kCompressorAt = 0;
constexpr std::size_t kCoderAt = 2;
constexpr std::size_t kChunkSizeAt = 12;
constexpr std::size_t kItemCountAt = 32;
constexpr std::size_t kItemsAt = 34;
constexpr std::size_t kItemBytes = 6;

// Each extra byte has its own models (about 2.3 KB per byte, per scanner channel in layered
// chunks, per chunk decoded at once), so a record of 64 KB of extra bytes would cost hundreds
// of megabytes whatever the file's size. Real files carry a few dozen.
constexpr std::uint16_t kMaxExtraBytes = 1024;

template <typename T> T load(std::span<const std::uint8_t> bytes, std::size_t at) {
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof value);
    return value;
}

// The items a point format's records consist of, before any extra bytes.
std::vector<ItemType> itemsOfFormat(std::uint8_t format) {
    using T = ItemType;
    switch (format) {
    case 0:
        return {T::Point10};
    case 1:
        return {T::Point10, T::GpsTime11};
    case 2:
        return {T::Point10, T::Rgb12};
    case 3:
        return {T::Point10, T::GpsTime11, T::Rgb12};
    case 4:
        return {T::Point10, T::GpsTime11, T::WavePacket13};
    case 5:
        return {T::Point10, T::GpsTime11, T::Rgb12, T::WavePacket13};
    case 6:
        return {T::Point14};
    case 7:
        return {T::Point14, T::Rgb14};
    case 8:
        return {T::Point14, T::RgbNir14};
    case 9:
        return {T::Point14, T::WavePacket14};
    default:
        return {T::Point14, T::RgbNir14, T::WavePacket14};
    }
}

std::uint16_t fixedItemSize(ItemType type) {
    switch (type) {
    case ItemType::Point10:
        return 20;
    case ItemType::GpsTime11:
        return 8;
    case ItemType::Rgb12:
    case ItemType::Rgb14:
        return 6;
    case ItemType::WavePacket13:
    case ItemType::WavePacket14:
        return 29;
    case ItemType::Point14:
        return 30;
    case ItemType::RgbNir14:
        return 8;
    default:
        return 0; // BYTE, BYTE14: any size
    }
}

bool isLayered(ItemType type) {
    return static_cast<std::uint16_t>(type) >= static_cast<std::uint16_t>(ItemType::Point14);
}

bool knownType(std::uint16_t type) {
    return type == 0 || (type >= 6 && type <= 14);
}

std::string itemName(std::uint16_t type) {
    return knownType(type) ? toString(static_cast<ItemType>(type))
                           : "unknown item type " + std::to_string(type);
}

class Parser {
public:
    Parser(std::span<const std::uint8_t> payload, const std::string& path, std::uint64_t offset,
           std::uint8_t pointFormat, std::uint16_t recordLength)
        : m_payload(payload), m_path(path), m_offset(offset), m_format(pointFormat),
          m_recordLength(recordLength) {}

    LaszipVlr parse() {
        if (m_payload.size() < kItemsAt) {
            fail(InputErrorKind::MalformedHeader, 0,
                 "the 'laszip encoded' record has " + std::to_string(m_payload.size()) +
                     " bytes, expected at least " + std::to_string(kItemsAt));
        }
        LaszipVlr vlr;
        parseCompressor(vlr);
        vlr.coder = load<std::uint16_t>(m_payload, kCoderAt);
        if (vlr.coder != 0) {
            fail(InputErrorKind::UnsupportedFeature, kCoderAt,
                 "LAZ coder " + std::to_string(vlr.coder) +
                     " is not supported, expected 0 (arithmetic)");
        }
        vlr.versionMajor = m_payload[4];
        vlr.versionMinor = m_payload[5];
        vlr.versionRevision = load<std::uint16_t>(m_payload, 6);
        vlr.options = load<std::uint32_t>(m_payload, 8);
        vlr.chunkSize = load<std::uint32_t>(m_payload, kChunkSizeAt);
        if (vlr.compressor == Compressor::Pointwise) {
            // One chunk, however many points: LASzip ignores the field here, and LASzip 1.x
            // wrote 0 or 1 into it.
            vlr.chunkSize = kVariableChunkSize;
        } else if (vlr.chunkSize == 0) {
            fail(InputErrorKind::MalformedHeader, kChunkSizeAt,
                 "LAZ chunk size 0, expected a number of points or 4294967295 (variable)");
        }
        parseItems(vlr);
        return vlr;
    }

private:
    [[noreturn]] void fail(InputErrorKind kind, std::size_t at, const std::string& detail) const {
        throw InputError(kind, m_path, InputLocation::byte(m_offset + at), detail);
    }

    void parseCompressor(LaszipVlr& vlr) const {
        const auto compressor = load<std::uint16_t>(m_payload, kCompressorAt);
        const bool layeredFormat = m_format >= 6;
        const std::string expected =
            layeredFormat ? "3 (layered chunks) for point format " + std::to_string(m_format)
                          : "1 or 2 (point-wise) for point format " + std::to_string(m_format);
        if (compressor == 0 || compressor > 3) {
            fail(InputErrorKind::UnsupportedFeature, kCompressorAt,
                 "unknown LAZ compressor " + std::to_string(compressor) + ", expected " + expected);
        }
        if ((compressor == 3) != layeredFormat) {
            fail(InputErrorKind::UnsupportedFeature, kCompressorAt,
                 "LAZ compressor " + std::to_string(compressor) + " does not fit, expected " +
                     expected);
        }
        vlr.compressor = static_cast<Compressor>(compressor);
    }

    void parseItems(LaszipVlr& vlr) const {
        const auto count = load<std::uint16_t>(m_payload, kItemCountAt);
        if (m_payload.size() < kItemsAt + count * kItemBytes) {
            fail(InputErrorKind::MalformedHeader, kItemCountAt,
                 "the 'laszip encoded' record lists " + std::to_string(count) + " items (" +
                     std::to_string(kItemsAt + count * kItemBytes) + " bytes) but has " +
                     std::to_string(m_payload.size()) + " bytes");
        }
        const std::vector<ItemType> expected = itemsOfFormat(m_format);
        std::size_t recordBytes = 0;
        for (std::size_t i = 0; i < count; ++i) {
            const std::size_t at = kItemsAt + i * kItemBytes;
            const auto type = load<std::uint16_t>(m_payload, at);
            const auto size = load<std::uint16_t>(m_payload, at + 2);
            const auto version = load<std::uint16_t>(m_payload, at + 4);
            checkItem(i, at, type, expected);
            const Item item{static_cast<ItemType>(type), size, version};
            checkSizeAndVersion(item, at);
            vlr.items.push_back(item);
            recordBytes += size;
        }
        if (count < expected.size()) {
            fail(InputErrorKind::MalformedHeader, kItemCountAt,
                 "the 'laszip encoded' record lists " + std::to_string(count) +
                     " items, expected at least " + std::to_string(expected.size()) +
                     " for point format " + std::to_string(m_format) + " (missing " +
                     toString(expected[count]) + ")");
        }
        if (recordBytes != m_recordLength) {
            fail(InputErrorKind::MalformedHeader, kItemCountAt,
                 "the LAZ items fill " + std::to_string(recordBytes) +
                     "-byte records, but the header's point record length is " +
                     std::to_string(m_recordLength));
        }
    }

    // Items come in the point format's order, then at most one item of extra bytes.
    void checkItem(std::size_t index, std::size_t at, std::uint16_t type,
                   const std::vector<ItemType>& expected) const {
        const ItemType extraBytes = m_format >= 6 ? ItemType::Byte14 : ItemType::Byte;
        const std::uint16_t wanted =
            static_cast<std::uint16_t>(index < expected.size() ? expected[index] : extraBytes);
        if (!knownType(type)) {
            fail(InputErrorKind::UnsupportedFeature, at,
                 "LAZ item " + std::to_string(index) + " has " + itemName(type) + ", expected " +
                     itemName(wanted));
        }
        if (type != wanted || index > expected.size()) {
            fail(InputErrorKind::MalformedHeader, at,
                 "LAZ item " + std::to_string(index) + " is " + itemName(type) + ", expected " +
                     (index > expected.size() ? std::string("no more items") : itemName(wanted)) +
                     " for point format " + std::to_string(m_format));
        }
    }

    void checkSizeAndVersion(const Item& item, std::size_t at) const {
        const std::uint16_t fixed = fixedItemSize(item.type);
        if ((fixed != 0 && item.size != fixed) || item.size == 0) {
            fail(InputErrorKind::MalformedHeader, at + 2,
                 std::string("LAZ item ") + toString(item.type) + " has size " +
                     std::to_string(item.size) + ", expected " +
                     (fixed != 0 ? std::to_string(fixed) : std::string("at least 1")));
        }
        const bool extraBytes = item.type == ItemType::Byte || item.type == ItemType::Byte14;
        if (extraBytes && item.size > kMaxExtraBytes) {
            fail(InputErrorKind::UnsupportedFeature, at + 2,
                 "LAZ extra bytes item of " + std::to_string(item.size) +
                     " bytes a point: at most " + std::to_string(kMaxExtraBytes) +
                     " are supported");
        }
        const bool supported = isLayered(item.type) ? (item.version >= 2 && item.version <= 4)
                                                    : (item.version == 1 || item.version == 2);
        if (!supported) {
            fail(InputErrorKind::UnsupportedFeature, at + 4,
                 std::string("LAZ item ") + toString(item.type) + " version " +
                     std::to_string(item.version) + " is not supported, expected " +
                     (isLayered(item.type) ? "3 or 4" : "1 or 2"));
        }
    }

    std::span<const std::uint8_t> m_payload;
    const std::string& m_path;
    std::uint64_t m_offset;
    std::uint8_t m_format;
    std::uint16_t m_recordLength;
};

} // namespace

const char* toString(ItemType type) {
    switch (type) {
    case ItemType::Byte:
        return "BYTE";
    case ItemType::Point10:
        return "POINT10";
    case ItemType::GpsTime11:
        return "GPSTIME11";
    case ItemType::Rgb12:
        return "RGB12";
    case ItemType::WavePacket13:
        return "WAVEPACKET13";
    case ItemType::Point14:
        return "POINT14";
    case ItemType::Rgb14:
        return "RGB14";
    case ItemType::RgbNir14:
        return "RGBNIR14";
    case ItemType::WavePacket14:
        return "WAVEPACKET14";
    case ItemType::Byte14:
        return "BYTE14";
    }
    return "unknown";
}

std::string LaszipVlr::describe() const {
    std::string text = compressor == Compressor::LayeredChunked     ? "layered chunks"
                       : compressor == Compressor::PointwiseChunked ? "point-wise chunks"
                                                                    : "point-wise, one chunk";
    text += " (";
    for (std::size_t i = 0; i < items.size(); ++i) {
        text += (i ? ", " : "") + std::string(toString(items[i].type)) + " v" +
                std::to_string(items[i].version);
    }
    return text + ")";
}

LaszipVlr parseLaszipVlr(std::span<const std::uint8_t> payload, const std::string& path,
                         std::uint64_t payloadOffset, std::uint8_t pointFormat,
                         std::uint16_t recordLength) {
    return Parser(payload, path, payloadOffset, pointFormat, recordLength).parse();
}

} // namespace omicron::laz
