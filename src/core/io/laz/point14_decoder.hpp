// The POINT14 item, versions 3 and 4: the 30 bytes every LAS 1.4 point record of formats 6 to
// 10 starts with, in nine layers: (0) scanner channel, returns, x and y; (1) z;
// (2) classification; (3) flags; (4) intensity; (5) scan angle; (6) user data; (7) point source
// ID; (8) GPS time. The first layer's change mask says which fields changed; each field is
// predicted in the context of the point's return number and number of returns, and whether its
// GPS time changed, with separate models and predictions per scanner channel.
#pragma once

#include "io/laz/layered_item_decoder.hpp"
#include "io/laz/point14_context.hpp"

namespace omicron::laz {

inline constexpr std::size_t kPoint14Bytes = 30;
inline constexpr std::size_t kPoint14Layers = 9;

// Not a LayeredItemDecoder: the chunk decoder calls it first, for a slice of points at once,
// and the other items follow the channels it reports.
class Point14Decoder {
public:
    Point14Decoder();
    ~Point14Decoder();

    // Starts a chunk from its first point's item (stored raw) in scanner channel `channel`;
    // the kPoint14Layers `layers` (already started over their bytes) outlive the decoder.
    void start(const std::uint8_t* firstItem, std::uint32_t channel, std::span<Layer> layers);
    // Decodes the next `count` points into the items at `items`, `stride` bytes apart, the
    // first layer over all of them, then the other layers a few at a time over all of them
    // (each layer is its own stream); `channels` receives each point's scanner channel.
    void decode(std::uint8_t* items, std::size_t count, std::size_t stride, std::uint8_t* channels);

    // The scanner channel stored in a raw POINT14 item.
    static std::uint32_t channelOf(const std::uint8_t* item) { return (item[15] >> 4) & 3u; }

private:
    // What the first layer tells the others about one point.
    struct PointContext {
        std::uint8_t channel;  // its scanner channel: whose context and predictions
        std::uint8_t opened;   // 1: its channel's context opened here, from the point before
        std::uint8_t changed;  // the change mask
        std::uint8_t position; // single (3), first (2), last (1) or intermediate (0) return
        std::uint8_t level;    // the return level of Z's predictions
        std::uint8_t zModel;   // Z's magnitude-class model
        std::uint8_t gpsBit;   // the GPS time changed
    };

    void decodeChannelReturnsXY(std::uint8_t* items, std::size_t count, std::size_t stride);
    // Other layers over the points, in one loop: each `field(context, before, point, item)`
    // decodes (or, for a layer of 0 bytes, keeps) one point's field in its channel's context,
    // `before` being the context of the point before when the channel opened at this point,
    // else null.
    template <typename... Field>
    void decodeLayers(std::uint8_t* items, std::size_t count, std::size_t stride,
                      std::uint32_t startChannel, Field... fields);

    std::span<Layer> m_layers;
    std::vector<PointContext> m_points; // the slice being decoded
    point14::Contexts m_contexts;
};

} // namespace omicron::laz
