#include "reference_point14_decoder.hpp"

#include "io/laz/point14_decoder.hpp"
#include "io/laz/return_contexts.hpp"
#include "io/raw_bytes.hpp"

#include <cassert>

namespace omicron::laz::test {

namespace {

enum LayerIndex : std::size_t {
    kChannelReturnsXY,
    kZ,
    kClassification,
    kFlags,
    kIntensity,
    kScanAngle,
    kUserData,
    kPointSource,
    kGpsTime,
};

// The first layer's change mask.
constexpr unsigned kChannelChanged = 1u << 6;
constexpr unsigned kPointSourceChanged = 1u << 5;
constexpr unsigned kGpsTimeChanged = 1u << 4;
constexpr unsigned kScanAngleChanged = 1u << 3;
constexpr unsigned kNumberOfReturnsChanged = 1u << 2;
constexpr unsigned kReturnNumberChange = 3u; // 0 same, 1 plus one, 2 minus one, 3 coded

std::uint32_t evenClass(std::uint32_t k, std::uint32_t limit) {
    return k < limit ? (k & ~1u) : limit;
}

} // namespace

// One scanner channel's models and predictions.
struct ReferencePoint14Decoder::Context {
    explicit Context(const Fields& from)
        : last(from), gpsTime(GpsTimeDecoder::Alphabet::ChangedOnly, from.gpsTimeBits) {
        lastZ.fill(from.z);
        lastIntensity.fill(from.intensity);
    }

    Fields last;
    bool lastGpsTimeChanged = false;

    std::array<SymbolModel, 8> changedValues{SymbolModel(128), SymbolModel(128), SymbolModel(128),
                                             SymbolModel(128), SymbolModel(128), SymbolModel(128),
                                             SymbolModel(128), SymbolModel(128)};
    SymbolModel scannerChannel{3};
    std::array<std::unique_ptr<SymbolModel>, 16> numberOfReturns;
    std::array<std::unique_ptr<SymbolModel>, 16> returnNumber;
    SymbolModel returnNumberGpsSame{13};
    IntegerDecoder dx{32, 2};
    IntegerDecoder dy{32, 22};
    IntegerDecoder z{32, 20};
    std::array<std::unique_ptr<SymbolModel>, 64> classification;
    std::array<std::unique_ptr<SymbolModel>, 64> flags;
    std::array<std::unique_ptr<SymbolModel>, 64> userData;
    IntegerDecoder intensity{16, 4};
    IntegerDecoder scanAngle{16, 2};
    IntegerDecoder pointSourceId{16};
    GpsTimeDecoder gpsTime;

    std::array<StreamingMedian5, 12> xDiffMedian;
    std::array<StreamingMedian5, 12> yDiffMedian;
    std::array<std::int32_t, 8> lastZ{};
    std::array<std::uint16_t, 8> lastIntensity{};
};

ReferencePoint14Decoder::ReferencePoint14Decoder() = default;
ReferencePoint14Decoder::~ReferencePoint14Decoder() = default;

ReferencePoint14Decoder::Fields ReferencePoint14Decoder::Fields::load(const std::uint8_t* item) {
    Fields f;
    f.x = loadRaw<std::int32_t>(item);
    f.y = loadRaw<std::int32_t>(item + 4);
    f.z = loadRaw<std::int32_t>(item + 8);
    f.intensity = loadRaw<std::uint16_t>(item + 12);
    f.returnNumber = item[14] & 15u;
    f.numberOfReturns = item[14] >> 4;
    f.classFlags = item[15] & 15u;
    f.scannerChannel = (item[15] >> 4) & 3u;
    f.scanDirection = (item[15] >> 6) & 1u;
    f.edgeOfFlightLine = item[15] >> 7;
    f.classification = item[16];
    f.userData = item[17];
    f.scanAngle = loadRaw<std::int16_t>(item + 18);
    f.pointSourceId = loadRaw<std::uint16_t>(item + 20);
    f.gpsTimeBits = loadRaw<std::uint64_t>(item + 22);
    return f;
}

void ReferencePoint14Decoder::Fields::store(std::uint8_t* item) const {
    storeRaw(item, x);
    storeRaw(item + 4, y);
    storeRaw(item + 8, z);
    storeRaw(item + 12, intensity);
    item[14] = static_cast<std::uint8_t>(returnNumber | (numberOfReturns << 4));
    item[15] = static_cast<std::uint8_t>(classFlags | (scannerChannel << 4) | (scanDirection << 6) |
                                         (edgeOfFlightLine << 7));
    item[16] = classification;
    item[17] = userData;
    storeRaw(item + 18, scanAngle);
    storeRaw(item + 20, pointSourceId);
    storeRaw(item + 22, gpsTimeBits);
}

ReferencePoint14Decoder::Context& ReferencePoint14Decoder::open(std::uint32_t channel,
                                                                const Fields& from) {
    m_contexts[channel] = std::make_unique<Context>(from);
    return *m_contexts[channel];
}

void ReferencePoint14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                                    std::span<Layer> layers) {
    assert(layers.size() == kPoint14Layers);
    m_layers = layers;
    m_current = channel & 3u;
    open(m_current, Fields::load(firstItem));
}

void ReferencePoint14Decoder::decode(std::uint8_t* item) {
    ArithmeticDecoder& xy = m_layers[kChannelReturnsXY].decoder;
    Context& previous = *m_contexts[m_current];
    const Fields& before = previous.last;

    // The change mask's model: was the last point a first return, a last return, and did its
    // GPS time change?
    const std::uint32_t lastReturnContext =
        (before.returnNumber == 1 ? 1u : 0u) |
        (before.returnNumber >= before.numberOfReturns ? 2u : 0u) |
        (previous.lastGpsTimeChanged ? 4u : 0u);
    const unsigned changed = xy.decodeSymbol(previous.changedValues[lastReturnContext]);

    if (changed & kChannelChanged) {
        const std::uint32_t step = xy.decodeSymbol(previous.scannerChannel);
        const std::uint32_t channel = (m_current + step + 1) & 3u;
        if (!m_contexts[channel]) {
            open(channel, before); // a channel's first point predicts from the point before
        }
        m_current = channel;
        m_contexts[channel]->last.scannerChannel = channel;
    }
    Context& c = *m_contexts[m_current];
    Fields& p = c.last;
    const bool gpsTimeChanged = (changed & kGpsTimeChanged) != 0;
    const std::uint32_t gpsBit = gpsTimeChanged ? 1u : 0u;

    std::uint32_t n = p.numberOfReturns;
    if (changed & kNumberOfReturnsChanged) {
        n = xy.decodeSymbol(lazyModel(c.numberOfReturns, n, 16));
        p.numberOfReturns = n;
    }
    std::uint32_t r = p.returnNumber;
    switch (changed & kReturnNumberChange) {
    case 0:
        break;
    case 1:
        r = (r + 1) & 15u;
        break;
    case 2:
        r = (r + 15) & 15u;
        break;
    default:
        if (gpsTimeChanged) {
            r = xy.decodeSymbol(lazyModel(c.returnNumber, r, 16));
        } else {
            r = (r + xy.decodeSymbol(c.returnNumberGpsSame) + 2) & 15u;
        }
        break;
    }
    p.returnNumber = r;

    const std::uint32_t map = returnMap6(n, r);
    const std::uint32_t level = returnLevel8Of16(n, r);
    // Single (3), first (2), last (1) or intermediate (0) return.
    const std::uint32_t position = (r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u);
    const std::uint32_t single = n == 1 ? 1u : 0u;

    const std::size_t medianIndex = (map << 1) | gpsBit;
    const std::int32_t dx = c.dx.decode(xy, c.xDiffMedian[medianIndex].median(), single);
    p.x = wrappingAdd(p.x, dx);
    c.xDiffMedian[medianIndex].add(dx);
    const std::int32_t dy =
        c.dy.decode(xy, c.yDiffMedian[medianIndex].median(), single + evenClass(c.dx.k(), 20));
    p.y = wrappingAdd(p.y, dy);
    c.yDiffMedian[medianIndex].add(dy);

    if (m_layers[kZ].present) {
        const std::uint32_t zClass = (c.dx.k() + c.dy.k()) / 2;
        p.z = c.z.decode(m_layers[kZ].decoder, c.lastZ[level], single + evenClass(zClass, 18));
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
    if (m_layers[kGpsTime].present && gpsTimeChanged) {
        p.gpsTimeBits = c.gpsTime.decode(m_layers[kGpsTime].decoder);
    }
    c.lastGpsTimeChanged = gpsTimeChanged;
    p.store(item);
}

} // namespace omicron::laz::test
