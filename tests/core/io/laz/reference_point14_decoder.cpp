#include "reference_point14_decoder.hpp"

#include "io/laz/point14_decoder.hpp"

#include <cassert>

namespace omicron::laz::test {

using namespace point14;

namespace {

void store(const Fields& f, std::uint8_t* item) {
    storeRaw(item, f.x);
    storeRaw(item + 4, f.y);
    storeRaw(item + 8, f.z);
    storeRaw(item + 12, f.intensity);
    item[14] = static_cast<std::uint8_t>(f.returnNumber | (f.numberOfReturns << 4));
    item[15] = static_cast<std::uint8_t>(f.classFlags | (f.scannerChannel << 4) |
                                         (f.scanDirection << 6) | (f.edgeOfFlightLine << 7));
    item[16] = f.classification;
    item[17] = f.userData;
    storeRaw(item + 18, f.scanAngle);
    storeRaw(item + 20, f.pointSourceId);
    storeRaw(item + 22, f.gpsTimeBits);
}

} // namespace

void ReferencePoint14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                                    std::span<Layer> layers) {
    assert(layers.size() == kPoint14Layers);
    m_layers = layers;
    m_contexts.current = channel & 3u;
    m_contexts.open(m_contexts.current, Fields::load(firstItem));
}

void ReferencePoint14Decoder::decode(std::uint8_t* item) {
    // A context opened by the first layer copied every field of the point before, which this
    // decoder has decoded entirely.
    const FirstLayerPoint first = decodeFirstLayer(m_layers[kChannelReturnsXY].decoder, m_contexts);
    Context& c = *m_contexts.slots[m_contexts.current];
    Fields& p = c.last;
    const unsigned changed = first.changed;
    const std::uint32_t gpsBit = (changed & kGpsTimeChanged) != 0 ? 1u : 0u;
    const std::uint32_t level = returnLevel8Of16(first.n, first.r);
    const std::uint32_t position = (first.r == 1 ? 2u : 0u) + (first.r >= first.n ? 1u : 0u);

    if (m_layers[kZ].present) {
        const std::uint32_t zClass = (c.dx.k() + c.dy.k()) / 2;
        p.z =
            c.z.decode(m_layers[kZ].decoder, c.lastZ[level], first.single + evenClass(zClass, 18));
        c.lastZ[level] = p.z;
    }
    if (m_layers[kClassification].present) {
        const std::size_t index = ((p.classification & 0x1Fu) << 1) + (position == 3 ? 1u : 0u);
        p.classification = static_cast<std::uint8_t>(m_layers[kClassification].decoder.decodeSymbol(
            lazyModel(c.classification, index, 256)));
    }
    if (m_layers[kFlags].present) {
        const std::size_t lastFlags =
            (p.edgeOfFlightLine << 5) | (p.scanDirection << 4) | p.classFlags;
        const std::uint32_t flags =
            m_layers[kFlags].decoder.decodeSymbol(lazyModel(c.flags, lastFlags, 64));
        p.edgeOfFlightLine = (flags >> 5) & 1u;
        p.scanDirection = (flags >> 4) & 1u;
        p.classFlags = flags & 15u;
    }
    if (m_layers[kIntensity].present) {
        const std::size_t index = (position << 1) | gpsBit;
        p.intensity = static_cast<std::uint16_t>(
            c.intensity.decode(m_layers[kIntensity].decoder, c.lastIntensity[index], position));
        c.lastIntensity[index] = p.intensity;
    }
    if (m_layers[kScanAngle].present && (changed & kScanAngleChanged)) {
        p.scanAngle = static_cast<std::int16_t>(
            c.scanAngle.decode(m_layers[kScanAngle].decoder, p.scanAngle, gpsBit));
    }
    if (m_layers[kUserData].present) {
        p.userData = static_cast<std::uint8_t>(
            m_layers[kUserData].decoder.decodeSymbol(lazyModel(c.userData, p.userData / 4u, 256)));
    }
    if (m_layers[kPointSource].present && (changed & kPointSourceChanged)) {
        p.pointSourceId = static_cast<std::uint16_t>(
            c.pointSourceId.decode(m_layers[kPointSource].decoder, p.pointSourceId));
    }
    if (m_layers[kGpsTime].present && gpsBit != 0) {
        p.gpsTimeBits = c.gpsTime.decode(m_layers[kGpsTime].decoder);
    }
    store(p, item);
}

} // namespace omicron::laz::test
