#include "io/laz/chunk_decoder.hpp"

#include "io/input_error.hpp"
#include "io/laz/byte14_decoder.hpp"
#include "io/laz/byte_decoder.hpp"
#include "io/laz/gpstime_decoder.hpp"
#include "io/laz/items_v1.hpp"
#include "io/laz/point10_decoder.hpp"
#include "io/laz/rgb14_decoder.hpp"
#include "io/laz/rgb_decoder.hpp"
#include "io/laz/wavepacket_decoder.hpp"

#include <cassert>
#include <cstring>

namespace omicron::laz {

namespace {

constexpr const char* kPoint14LayerNames[kPoint14Layers] = {"channel, returns and x/y",
                                                            "z",
                                                            "classification",
                                                            "flags",
                                                            "intensity",
                                                            "scan angle",
                                                            "user data",
                                                            "point source ID",
                                                            "GPS time"};

// The decoder of an item's version: 1 is LASzip 1.x's coding of the same item (parseLaszipVlr
// admits 1 and 2).
template <typename Version1, typename Version2, typename... Arguments>
std::unique_ptr<PointwiseItemDecoder> byVersion(const Item& item, Arguments... arguments) {
    if (item.version == 1) {
        return std::make_unique<Version1>(arguments...);
    }
    return std::make_unique<Version2>(arguments...);
}

std::unique_ptr<PointwiseItemDecoder> makePointwise(const Item& item) {
    switch (item.type) {
    case ItemType::Point10:
        return byVersion<Point10V1Decoder, Point10Decoder>(item);
    case ItemType::GpsTime11:
        return byVersion<GpsTime11V1Decoder, GpsTime11Decoder>(item);
    case ItemType::Rgb12:
        return byVersion<Rgb12V1Decoder, Rgb12Decoder>(item);
    case ItemType::Byte:
        return byVersion<ByteV1Decoder, ByteDecoder>(item, std::size_t{item.size});
    case ItemType::WavePacket13: // coded as version 1 in every version
        return std::make_unique<WavePacket13Decoder>();
    default:
        break;
    }
    assert(false && "parseLaszipVlr admits no other point-wise item");
    return nullptr;
}

std::unique_ptr<LayeredItemDecoder> makeLayered(const Item& item) {
    // Version 2 came from a prototype and is decoded as version 3, as LASzip does.
    const std::uint32_t version = item.version == 4 ? 4 : 3;
    switch (item.type) {
    case ItemType::Rgb14:
        return std::make_unique<Rgb14Decoder>(false, version);
    case ItemType::RgbNir14:
        return std::make_unique<Rgb14Decoder>(true, version);
    case ItemType::WavePacket14:
        return std::make_unique<WavePacket14Decoder>(version);
    case ItemType::Byte14:
        return std::make_unique<Byte14Decoder>(item.size, version);
    default:
        break;
    }
    assert(false && "parseLaszipVlr admits no other layered item after POINT14");
    return nullptr;
}

std::vector<std::string> layerNames(const Item& item) {
    switch (item.type) {
    case ItemType::Rgb14:
        return {"RGB"};
    case ItemType::RgbNir14:
        return {"RGB", "NIR"};
    case ItemType::WavePacket14:
        return {"wave packet"};
    default:
        break;
    }
    std::vector<std::string> names;
    for (std::size_t i = 0; i < item.size; ++i) {
        names.push_back("extra byte " + std::to_string(i));
    }
    return names;
}

std::string range(std::uint64_t first, std::uint64_t count) {
    return std::to_string(first) + " to " + std::to_string(first + count - 1);
}

} // namespace

ChunkDecoder::ChunkDecoder(const LaszipVlr& vlr) : m_vlr(vlr) {
    for (const Item& item : vlr.items) {
        m_itemOffsets.push_back(m_recordLength);
        m_recordLength += item.size;
    }
}

ChunkDecoder::~ChunkDecoder() = default;

void ChunkDecoder::fail(std::uint64_t byteInChunk, const std::string& detail,
                        InputErrorKind kind) const {
    const Chunk& chunk = m_context.chunk;
    throw InputError(kind, *m_context.path, InputLocation::byte(chunk.offset + byteInChunk),
                     "LAZ chunk " + std::to_string(m_context.index) + " of " +
                         std::to_string(m_context.count) + " (points " +
                         range(chunk.firstPoint, chunk.pointCount) + ", bytes " +
                         range(chunk.offset, chunk.bytes) + "): " + detail);
}

void ChunkDecoder::start(std::span<const std::uint8_t> bytes, const ChunkContext& context) {
    assert(bytes.size() == context.chunk.bytes && bytes.size() >= m_recordLength);
    m_bytes = bytes;
    m_context = context;
    m_decoded = 0;
    if (m_vlr.compressor == Compressor::LayeredChunked) {
        startLayered();
    } else {
        startPointwise();
    }
}

void ChunkDecoder::startPointwise() {
    m_pointwise.clear();
    for (std::size_t i = 0; i < m_vlr.items.size(); ++i) {
        m_pointwise.push_back(makePointwise(m_vlr.items[i]));
        m_pointwise.back()->start(m_bytes.data() + m_itemOffsets[i]);
    }
    m_stream.start(m_bytes.data() + m_recordLength, m_bytes.data() + m_bytes.size());
}

void ChunkDecoder::startLayered() {
    m_point14 = std::make_unique<Point14Decoder>();
    m_layered.clear();
    m_layerNames.clear();
    for (const char* name : kPoint14LayerNames) {
        m_layerNames.emplace_back(name);
    }
    for (std::size_t i = 1; i < m_vlr.items.size(); ++i) {
        m_layered.push_back(makeLayered(m_vlr.items[i]));
        for (std::string& name : layerNames(m_vlr.items[i])) {
            m_layerNames.push_back(std::move(name));
        }
    }
    const std::size_t layerCount = m_layerNames.size();

    // The point count and the layer sizes follow the raw first record.
    std::uint64_t at = m_recordLength;
    const std::uint64_t headerBytes = 4 + 4 * std::uint64_t{layerCount};
    if (m_bytes.size() < at + headerBytes) {
        fail(at, "expected its point count and " + std::to_string(layerCount) + " layer sizes (" +
                     std::to_string(headerBytes) +
                     " bytes) after the first "
                     "point, but the chunk ends at byte " +
                     std::to_string(m_bytes.size()));
    }
    std::uint32_t count;
    std::memcpy(&count, m_bytes.data() + at, sizeof count);
    if (count != m_context.chunk.pointCount) {
        fail(at,
             "the chunk says it holds " + std::to_string(count) + " points, but the chunk " +
                 "table and the header's point count give it " +
                 std::to_string(m_context.chunk.pointCount),
             InputErrorKind::CountMismatch);
    }
    at += 4;
    m_layerSizes.assign(layerCount, 0);
    std::uint64_t layerBytes = 0;
    for (std::size_t i = 0; i < layerCount; ++i) {
        std::uint32_t size;
        std::memcpy(&size, m_bytes.data() + at + 4 * i, sizeof size);
        m_layerSizes[i] = size;
        layerBytes += size;
    }
    at += 4 * layerCount;
    if (at + layerBytes != m_bytes.size()) {
        fail(m_recordLength + 4,
             "its layers add up to " + std::to_string(layerBytes) + " bytes, but the chunk has " +
                 std::to_string(m_bytes.size() - at) + " bytes after its layer sizes");
    }
    // Layers stay where they are in the chunk's buffer; each decoder reads its own span.
    m_layers.assign(layerCount, Layer{});
    m_layerStarts.assign(layerCount, 0);
    for (std::size_t i = 0; i < layerCount; ++i) {
        m_layerStarts[i] = at;
        if (m_layerSizes[i] != 0) {
            m_layers[i].present = true;
            m_layers[i].decoder.start(m_bytes.data() + at, m_bytes.data() + at + m_layerSizes[i]);
        }
        at += m_layerSizes[i];
    }
    if (!m_layers[0].present && m_context.chunk.pointCount > 1) {
        fail(m_layerStarts[0], "its first layer (" + m_layerNames[0] +
                                   ") is empty, but the "
                                   "chunk holds more than one point");
    }

    const std::uint8_t* first = m_bytes.data();
    const std::uint32_t channel = Point14Decoder::channelOf(first);
    std::span<Layer> layers(m_layers);
    m_point14->start(first, channel, layers.subspan(0, kPoint14Layers));
    std::size_t nextLayer = kPoint14Layers;
    for (std::size_t i = 0; i < m_layered.size(); ++i) {
        const std::size_t count = m_layered[i]->layerCount();
        m_layered[i]->start(first + m_itemOffsets[i + 1], channel,
                            layers.subspan(nextLayer, count));
        nextLayer += count;
    }
}

void ChunkDecoder::decode(std::uint8_t* records, std::uint64_t count) {
    assert(count <= remaining());
    if (count == 0) {
        return;
    }
    if (m_decoded == 0) { // the first point is stored raw
        std::memcpy(records, m_bytes.data(), m_recordLength);
        records += m_recordLength;
        --count;
        ++m_decoded;
    }
    if (m_vlr.compressor == Compressor::LayeredChunked) {
        decodeLayered(records, count);
    } else {
        decodePointwise(records, count);
    }
    m_decoded += count;
    checkAfterDecode();
}

void ChunkDecoder::decodePointwise(std::uint8_t* records, std::uint64_t count) {
    const std::size_t items = m_pointwise.size();
    for (std::uint64_t p = 0; p < count; ++p) {
        std::uint8_t* record = records + p * m_recordLength;
        for (std::size_t i = 0; i < items; ++i) {
            m_pointwise[i]->decode(m_stream, record + m_itemOffsets[i]);
        }
    }
}

// An item at a time over the points (POINT14 a few layers at a time), not a point at a time over
// the items: the layers are independent streams (the other items only need each point's scanner
// channel from POINT14), and one stream's loop keeps its state and branch history to itself.
void ChunkDecoder::decodeLayered(std::uint8_t* records, std::uint64_t count) {
    m_channels.resize(count);
    m_point14->decode(records, count, m_recordLength, m_channels.data());
    for (std::size_t i = 0; i < m_layered.size(); ++i) {
        m_layered[i]->decode(records + m_itemOffsets[i + 1], count, m_recordLength,
                             m_channels.data());
    }
}

void ChunkDecoder::checkAfterDecode() {
    const bool finished = remaining() == 0;
    if (m_vlr.compressor != Compressor::LayeredChunked) {
        const std::uint64_t end = m_bytes.size();
        // A one-point chunk needs no stream: whatever follows its record is not read.
        if (m_stream.overran() && m_context.chunk.pointCount > 1) {
            fail(end, "its data ends before its " + std::to_string(m_context.chunk.pointCount) +
                          " points are decoded: the chunk is truncated or corrupt, or the "
                          "header declares more points than the file holds");
        }
        // The encoder flushes exactly the bytes its decoder reads, so a chunk that decodes
        // from fewer bytes than the table gives it is corrupt (or the table is).
        const std::uint64_t used = m_recordLength + m_stream.consumed();
        if (finished && m_context.exactEnd && m_context.chunk.pointCount > 1 && used != end) {
            fail(used, "its points decode from " + std::to_string(used) + " of its " +
                           std::to_string(end) +
                           " bytes: the chunk or the chunk table is "
                           "corrupt");
        }
        return;
    }
    for (std::size_t i = 0; i < m_layers.size(); ++i) {
        if (m_layers[i].present && m_layers[i].decoder.overran()) {
            fail(m_layerStarts[i] + m_layerSizes[i],
                 "its " + m_layerNames[i] + " layer (" + std::to_string(m_layerSizes[i]) +
                     " bytes from byte " +
                     std::to_string(m_context.chunk.offset + m_layerStarts[i]) +
                     ") ends before its points are decoded: the chunk is truncated or corrupt");
        }
    }
}

} // namespace omicron::laz
