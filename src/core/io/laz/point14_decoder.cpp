#include "io/laz/point14_decoder.hpp"

#include "io/laz/return_contexts.hpp"
#include "io/raw_bytes.hpp"

#include <bit>
#include <cassert>
#include <cstring>

static_assert(std::endian::native == std::endian::little, "LAS fields are stored with memcpy");

namespace omicron::laz {

using namespace point14;

Point14Decoder::Point14Decoder() = default;
Point14Decoder::~Point14Decoder() = default;

void Point14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                           std::span<Layer> layers) {
    assert(layers.size() == kPoint14Layers);
    m_layers = layers;
    m_contexts.current = channel & 3u;
    m_contexts.open(m_contexts.current, Fields::load(firstItem));
}

void Point14Decoder::decode(std::uint8_t* items, std::size_t count, std::size_t stride,
                            std::uint8_t* channels) {
    const std::uint32_t startChannel = m_contexts.current;
    m_points.resize(count);
    decodeChannelReturnsXY(items, count, stride);
    for (std::size_t i = 0; i < count; ++i) {
        channels[i] = m_points[i].channel;
    }
    // Each layer's field; a layer of 0 bytes keeps the field's value of its channel (which a
    // channel's first point takes from the point before, as every field does).
    const bool zPresent = m_layers[kZ].present;
    ArithmeticDecoder zDecoder = m_layers[kZ].decoder;
    const auto zField = [&](Context& c, const Context* before, const PointContext& p,
                            std::uint8_t* item) {
        if (before != nullptr) {
            c.last.z = before->last.z;
            c.lastZ.fill(before->last.z);
        }
        if (zPresent) {
            c.last.z = c.z.decode(zDecoder, c.lastZ[p.level], p.zModel);
            c.lastZ[p.level] = c.last.z;
        }
        storeRaw(item + 8, c.last.z);
    };
    const bool classPresent = m_layers[kClassification].present;
    ArithmeticDecoder classDecoder = m_layers[kClassification].decoder;
    const auto classificationField = [&](Context& c, const Context* before, const PointContext& p,
                                         std::uint8_t* item) {
        if (before != nullptr) {
            c.last.classification = before->last.classification;
        }
        if (classPresent) {
            const std::size_t index =
                ((c.last.classification & 0x1Fu) << 1) + (p.position == 3 ? 1u : 0u);
            c.last.classification = static_cast<std::uint8_t>(
                classDecoder.decodeSymbol(lazyModel(c.classification, index, 256)));
        }
        item[16] = c.last.classification;
    };
    const bool flagsPresent = m_layers[kFlags].present;
    ArithmeticDecoder flagsDecoder = m_layers[kFlags].decoder;
    const auto flagsField = [&](Context& c, const Context* before, const PointContext& p,
                                std::uint8_t* item) {
        Fields& f = c.last;
        if (before != nullptr) {
            f.edgeOfFlightLine = before->last.edgeOfFlightLine;
            f.scanDirection = before->last.scanDirection;
            f.classFlags = before->last.classFlags;
        }
        if (flagsPresent) {
            const std::size_t lastFlags =
                (f.edgeOfFlightLine << 5) | (f.scanDirection << 4) | f.classFlags;
            const std::uint32_t flags =
                flagsDecoder.decodeSymbol(lazyModel(c.flags, lastFlags, 64));
            f.edgeOfFlightLine = (flags >> 5) & 1u;
            f.scanDirection = (flags >> 4) & 1u;
            f.classFlags = flags & 15u;
        }
        item[15] = static_cast<std::uint8_t>(f.classFlags | (std::uint32_t{p.channel} << 4) |
                                             (f.scanDirection << 6) | (f.edgeOfFlightLine << 7));
    };
    const bool intensityPresent = m_layers[kIntensity].present;
    ArithmeticDecoder intensityDecoder = m_layers[kIntensity].decoder;
    const auto intensityField = [&](Context& c, const Context* before, const PointContext& p,
                                    std::uint8_t* item) {
        if (before != nullptr) {
            c.last.intensity = before->last.intensity;
            c.lastIntensity.fill(before->last.intensity);
        }
        if (intensityPresent) {
            const std::size_t index = (std::size_t{p.position} << 1) | p.gpsBit;
            c.last.intensity = static_cast<std::uint16_t>(
                c.intensity.decode(intensityDecoder, c.lastIntensity[index], p.position));
            c.lastIntensity[index] = c.last.intensity;
        }
        storeRaw(item + 12, c.last.intensity);
    };
    const bool scanAnglePresent = m_layers[kScanAngle].present;
    ArithmeticDecoder scanAngleDecoder = m_layers[kScanAngle].decoder;
    const auto scanAngleField = [&](Context& c, const Context* before, const PointContext& p,
                                    std::uint8_t* item) {
        if (before != nullptr) {
            c.last.scanAngle = before->last.scanAngle;
        }
        if (scanAnglePresent && (p.changed & kScanAngleChanged)) {
            c.last.scanAngle = static_cast<std::int16_t>(
                c.scanAngle.decode(scanAngleDecoder, c.last.scanAngle, p.gpsBit));
        }
        storeRaw(item + 18, c.last.scanAngle);
    };
    const bool userDataPresent = m_layers[kUserData].present;
    ArithmeticDecoder userDataDecoder = m_layers[kUserData].decoder;
    const auto userDataField = [&](Context& c, const Context* before, const PointContext&,
                                   std::uint8_t* item) {
        if (before != nullptr) {
            c.last.userData = before->last.userData;
        }
        if (userDataPresent) {
            c.last.userData = static_cast<std::uint8_t>(
                userDataDecoder.decodeSymbol(lazyModel(c.userData, c.last.userData / 4u, 256)));
        }
        item[17] = c.last.userData;
    };
    const bool pointSourcePresent = m_layers[kPointSource].present;
    ArithmeticDecoder pointSourceDecoder = m_layers[kPointSource].decoder;
    const auto pointSourceField = [&](Context& c, const Context* before, const PointContext& p,
                                      std::uint8_t* item) {
        if (before != nullptr) {
            c.last.pointSourceId = before->last.pointSourceId;
        }
        if (pointSourcePresent && (p.changed & kPointSourceChanged)) {
            c.last.pointSourceId = static_cast<std::uint16_t>(
                c.pointSourceId.decode(pointSourceDecoder, c.last.pointSourceId));
        }
        storeRaw(item + 20, c.last.pointSourceId);
    };
    const bool gpsPresent = m_layers[kGpsTime].present;
    ArithmeticDecoder gpsDecoder = m_layers[kGpsTime].decoder;
    const auto gpsTimeField = [&](Context& c, const Context* before, const PointContext& p,
                                  std::uint8_t* item) {
        if (before != nullptr) {
            c.last.gpsTimeBits = before->last.gpsTimeBits;
            c.gpsTime =
                GpsTimeDecoder(GpsTimeDecoder::Alphabet::ChangedOnly, before->last.gpsTimeBits);
        }
        if (gpsPresent && p.gpsBit != 0) {
            c.last.gpsTimeBits = c.gpsTime.decode(gpsDecoder);
        }
        storeRaw(item + 22, c.last.gpsTimeBits);
    };
    // A few layers per loop: each layer is one stream's dependency chain, and the chains of
    // one loop overlap. Grouped by weight: the two integer layers, the one-symbol layers (scan
    // angle and point source mostly unchanged), GPS time alone (its branches are its own).
    // terrascan_fmt8.laz on a Zen 4 host: 3 % faster than a loop per layer, 1 % faster than
    // one loop for all (on the Zen 5 host before, a loop per layer beat one for all by 2 %).
    decodeLayers(items, count, stride, startChannel, zField, intensityField);
    decodeLayers(items, count, stride, startChannel, classificationField, flagsField, userDataField,
                 scanAngleField, pointSourceField);
    decodeLayers(items, count, stride, startChannel, gpsTimeField);
    m_layers[kZ].decoder = zDecoder;
    m_layers[kClassification].decoder = classDecoder;
    m_layers[kFlags].decoder = flagsDecoder;
    m_layers[kIntensity].decoder = intensityDecoder;
    m_layers[kScanAngle].decoder = scanAngleDecoder;
    m_layers[kUserData].decoder = userDataDecoder;
    m_layers[kPointSource].decoder = pointSourceDecoder;
    m_layers[kGpsTime].decoder = gpsDecoder;
}

template <typename... Field>
void Point14Decoder::decodeLayers(std::uint8_t* items, std::size_t count, std::size_t stride,
                                  std::uint32_t startChannel, Field... fields) {
    std::uint32_t previous = startChannel;
    for (std::size_t i = 0; i < count; ++i, items += stride) {
        const PointContext& p = m_points[i];
        Context& c = *m_contexts.slots[p.channel];
        const Context* before = p.opened != 0 ? m_contexts.slots[previous].get() : nullptr;
        (fields(c, before, p, items), ...);
        previous = p.channel;
    }
}

void Point14Decoder::decodeChannelReturnsXY(std::uint8_t* items, std::size_t count,
                                            std::size_t stride) {
    // A copy in a local, put back after the loop: its state stays in registers.
    ArithmeticDecoder xy = m_layers[kChannelReturnsXY].decoder;
    for (std::size_t i = 0; i < count; ++i, items += stride) {
        const FirstLayerPoint first = decodeFirstLayer(xy, m_contexts);
        const Context& c = *m_contexts.slots[m_contexts.current];
        const std::uint32_t n = first.n;
        const std::uint32_t r = first.r;
        PointContext& out = m_points[i];
        out.channel = static_cast<std::uint8_t>(m_contexts.current);
        out.opened = first.opened ? 1 : 0;
        out.changed = static_cast<std::uint8_t>(first.changed);
        out.position = static_cast<std::uint8_t>((r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u));
        out.level = static_cast<std::uint8_t>(returnLevel8Of16(n, r));
        out.zModel =
            static_cast<std::uint8_t>(first.single + evenClass((c.dx.k() + c.dy.k()) / 2, 18));
        out.gpsBit = (first.changed & kGpsTimeChanged) != 0 ? 1 : 0;
        storeRaw(items, c.last.x);
        storeRaw(items + 4, c.last.y);
        items[14] = static_cast<std::uint8_t>(r | (n << 4));
    }
    m_layers[kChannelReturnsXY].decoder = xy;
}

} // namespace omicron::laz
