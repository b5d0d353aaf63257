#include "io/laz/point14_decoder.hpp"

#include "io/laz/return_contexts.hpp"
#include "io/raw_bytes.hpp"

#include <bit>
#include <cassert>
#include <cstring>

static_assert(std::endian::native == std::endian::little, "LAS fields are stored with memcpy");

namespace omicron::laz {

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
struct Point14Decoder::Context {
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

Point14Decoder::Point14Decoder() = default;
Point14Decoder::~Point14Decoder() = default;

Point14Decoder::Fields Point14Decoder::Fields::load(const std::uint8_t* item) {
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

Point14Decoder::Context& Point14Decoder::open(std::uint32_t channel, const Fields& from) {
    m_contexts[channel] = std::make_unique<Context>(from);
    return *m_contexts[channel];
}

void Point14Decoder::start(const std::uint8_t* firstItem, std::uint32_t channel,
                           std::span<Layer> layers) {
    assert(layers.size() == kPoint14Layers);
    m_layers = layers;
    m_current = channel & 3u;
    open(m_current, Fields::load(firstItem));
}

void Point14Decoder::decode(std::uint8_t* item, std::uint32_t /*channel*/) {
    std::uint8_t channel = 0;
    decode(item, 1, kPoint14Bytes, &channel);
}

void Point14Decoder::decode(std::uint8_t* items, std::size_t count, std::size_t stride,
                            std::uint8_t* channels) {
    const std::uint32_t startChannel = m_current;
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
    // A loop per layer: each is one stream's dependency chain, and in a loop of its own the
    // chain's state and branches stay predictable.
    decodeLayers(items, count, stride, startChannel, zField);
    decodeLayers(items, count, stride, startChannel, classificationField);
    decodeLayers(items, count, stride, startChannel, flagsField);
    decodeLayers(items, count, stride, startChannel, intensityField);
    decodeLayers(items, count, stride, startChannel, scanAngleField);
    decodeLayers(items, count, stride, startChannel, userDataField);
    decodeLayers(items, count, stride, startChannel, pointSourceField);
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
        Context& c = *m_contexts[p.channel];
        const Context* before = p.opened != 0 ? m_contexts[previous].get() : nullptr;
        (fields(c, before, p, items), ...);
        previous = p.channel;
    }
}

void Point14Decoder::decodeChannelReturnsXY(std::uint8_t* items, std::size_t count,
                                            std::size_t stride) {
    // A copy in a local, put back after the loop: its state stays in registers.
    ArithmeticDecoder xy = m_layers[kChannelReturnsXY].decoder;
    for (std::size_t i = 0; i < count; ++i, items += stride) {
        PointContext& out = m_points[i];
        out.opened = 0;
        Context& previous = *m_contexts[m_current];
        const Fields& before = previous.last;

        // The change mask's model: was the last point a first return, a last return, and did
        // its GPS time change?
        const std::uint32_t lastReturnContext =
            (before.returnNumber == 1 ? 1u : 0u) |
            (before.returnNumber >= before.numberOfReturns ? 2u : 0u) |
            (previous.lastGpsTimeChanged ? 4u : 0u);
        const unsigned changed = xy.decodeSymbol(previous.changedValues[lastReturnContext]);

        if (changed & kChannelChanged) {
            const std::uint32_t step = xy.decodeSymbol(previous.scannerChannel);
            const std::uint32_t channel = (m_current + step + 1) & 3u;
            if (!m_contexts[channel]) {
                // A channel's first point predicts from the point before: here its first
                // layer's fields; each other layer copies its own when it gets to the point.
                open(channel, before);
                out.opened = 1;
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
        const std::uint32_t single = n == 1 ? 1u : 0u;
        const std::size_t medianIndex = (map << 1) | gpsBit;
        const std::int32_t dx = c.dx.decode(xy, c.xDiffMedian[medianIndex].median(), single);
        p.x = wrappingAdd(p.x, dx);
        c.xDiffMedian[medianIndex].add(dx);
        const std::int32_t dy =
            c.dy.decode(xy, c.yDiffMedian[medianIndex].median(), single + evenClass(c.dx.k(), 20));
        p.y = wrappingAdd(p.y, dy);
        c.yDiffMedian[medianIndex].add(dy);
        c.lastGpsTimeChanged = gpsTimeChanged;

        out.channel = static_cast<std::uint8_t>(m_current);
        out.changed = static_cast<std::uint8_t>(changed);
        out.position = static_cast<std::uint8_t>((r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u));
        out.level = static_cast<std::uint8_t>(returnLevel8Of16(n, r));
        out.zModel = static_cast<std::uint8_t>(single + evenClass((c.dx.k() + c.dy.k()) / 2, 18));
        out.gpsBit = static_cast<std::uint8_t>(gpsBit);
        storeRaw(items, p.x);
        storeRaw(items + 4, p.y);
        items[14] = static_cast<std::uint8_t>(r | (n << 4));
    }
    m_layers[kChannelReturnsXY].decoder = xy;
}

} // namespace omicron::laz
