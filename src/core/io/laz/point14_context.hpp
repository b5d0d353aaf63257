// What the POINT14 decoder (point14_decoder) keeps per scanner channel, and its first layer's
// step: the change mask, the channel, the returns and x/y of one point. Shared with the test's
// point-at-a-time reference decoder (tests/core/io/laz/reference_point14_decoder), which
// differs only in the order it decodes the other layers in.
#pragma once

#include "io/laz/arithmetic_decoder.hpp"
#include "io/laz/gpstime_decoder.hpp"
#include "io/laz/integer_decoder.hpp"
#include "io/laz/return_contexts.hpp"
#include "io/laz/streaming_median.hpp"
#include "io/raw_bytes.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace omicron::laz::point14 {

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
inline constexpr unsigned kChannelChanged = 1u << 6;
inline constexpr unsigned kPointSourceChanged = 1u << 5;
inline constexpr unsigned kGpsTimeChanged = 1u << 4;
inline constexpr unsigned kScanAngleChanged = 1u << 3;
inline constexpr unsigned kNumberOfReturnsChanged = 1u << 2;
inline constexpr unsigned kReturnNumberChange = 3u; // 0 same, 1 plus one, 2 minus one, 3 coded

inline std::uint32_t evenClass(std::uint32_t k, std::uint32_t limit) {
    return k < limit ? (k & ~1u) : limit;
}

// The 30 bytes of a POINT14 item as fields.
struct Fields {
    std::int32_t x = 0, y = 0, z = 0;
    std::uint16_t intensity = 0;
    std::uint32_t returnNumber = 0;    // 4 bits
    std::uint32_t numberOfReturns = 0; // 4 bits
    std::uint32_t classFlags = 0;      // 4 bits
    std::uint32_t scannerChannel = 0;  // 2 bits
    std::uint32_t scanDirection = 0;
    std::uint32_t edgeOfFlightLine = 0;
    std::uint8_t classification = 0;
    std::uint8_t userData = 0;
    std::int16_t scanAngle = 0;
    std::uint16_t pointSourceId = 0;
    std::uint64_t gpsTimeBits = 0;

    static Fields load(const std::uint8_t* item);
};

inline Fields Fields::load(const std::uint8_t* item) {
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

// One scanner channel's models and predictions.
struct Context {
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

// The contexts of the channels seen so far in the chunk, and the current point's channel.
struct Contexts {
    std::array<std::unique_ptr<Context>, 4> slots;
    std::uint32_t current = 0;

    void open(std::uint32_t channel, const Fields& from) {
        slots[channel] = std::make_unique<Context>(from);
    }
};

// What the first layer decoded of one point, besides its fields in its context's `last`.
struct FirstLayerPoint {
    unsigned changed = 0; // the change mask
    bool opened = false;  // its channel's context opened at this point
    std::uint32_t n = 0;  // number of returns
    std::uint32_t r = 0;  // return number
    std::uint32_t single = 0;
};

// Decodes one point's first layer (channel, returns, x, y) from `xy` into its channel's context
// (contexts.current afterwards). Inline: the caller's loop keeps `xy` in registers.
inline FirstLayerPoint decodeFirstLayer(ArithmeticDecoder& xy, Contexts& contexts) {
    FirstLayerPoint point;
    Context& previous = *contexts.slots[contexts.current];
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
        const std::uint32_t channel = (contexts.current + step + 1) & 3u;
        if (!contexts.slots[channel]) {
            // A channel's first point predicts from the point before (every field: a
            // decoder that has not decoded the point before's other layers yet copies
            // them again when it has).
            contexts.open(channel, before);
            point.opened = true;
        }
        contexts.current = channel;
        contexts.slots[channel]->last.scannerChannel = channel;
    }
    Context& c = *contexts.slots[contexts.current];
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
    point.changed = changed;
    point.n = n;
    point.r = r;
    point.single = single;
    return point;
}

} // namespace omicron::laz::point14
