// One item (POINT14, RGB14, RGBNIR14, BYTE14) of a layered LAZ chunk, the compressor of point
// formats 6 to 10 (versions 3 and 4): a chunk stores its first point raw; each item then codes
// its fields in one or more layers, each layer its own arithmetic stream with its own byte
// count, so a layer can be decoded (or skipped) alone. A layer of 0 bytes means the field kept
// the first point's value throughout the chunk.
//
// Every item keeps one set of models and one last value per scanner channel (0-3): POINT14
// decodes the channel of each point and the other items follow it.
#pragma once

#include "io/laz/arithmetic_decoder.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace omicron::laz {

// One layer's stream; `present` is false for a layer of 0 bytes.
struct Layer {
    ArithmeticDecoder decoder;
    bool present = false;
};

class LayeredItemDecoder {
public:
    virtual ~LayeredItemDecoder() = default;

    // How many layers (and layer byte counts in the chunk) the item has.
    virtual std::size_t layerCount() const = 0;

    // Starts a chunk from its first point's item (stored raw) in scanner channel `channel`;
    // `layers` (layerCount() of them, already started over their bytes) outlive the decoder.
    virtual void start(const std::uint8_t* firstItem, std::uint32_t channel,
                       std::span<Layer> layers) = 0;

    // Decodes the next point's item into `item`; `channel` is the point's scanner channel, as
    // POINT14 decoded it.
    virtual void decode(std::uint8_t* item, std::uint32_t channel) = 0;

    // The next `count` points' items at `items`, `stride` bytes apart, in scanner channels
    // `channels`: a loop over decode(), unless an item keeps its layers' state in registers.
    virtual void decode(std::uint8_t* items, std::size_t count, std::size_t stride,
                        const std::uint8_t* channels) {
        for (std::size_t i = 0; i < count; ++i) {
            decode(items + i * stride, channels[i]);
        }
    }
};

// The per-channel state of RGB14, RGBNIR14 and BYTE14: `Models` (built from the item's byte
// count) and the last item's bytes. A channel's state is made when the channel first occurs in
// the chunk, from the item before it.
//
// Version 3 has a quirk that version 4 fixed, and a decoder must reproduce it: on a switch to a
// channel already seen in the chunk, version 3 keeps predicting from (and updating) the last
// item of the channel it switched from, with the new channel's models.
template <typename Models> class ChannelContexts {
public:
    ChannelContexts(std::size_t itemBytes, std::uint32_t version)
        : m_itemBytes(itemBytes), m_version(version) {}

    void start(const std::uint8_t* firstItem, std::uint32_t channel) {
        m_current = channel & 3;
        open(m_current, firstItem);
    }

    struct Selection {
        Models& models;
        std::uint8_t* last; // the item predicted from, updated by the decode
    };

    Selection select(std::uint32_t channel) {
        channel &= 3;
        std::uint8_t* last = m_contexts[m_current].last.data();
        if (channel != m_current) {
            m_current = channel;
            Context& next = m_contexts[channel];
            if (!next.models) {
                open(channel, last);
                last = next.last.data();
            } else if (m_version >= 4) {
                last = next.last.data();
            }
        }
        return {*m_contexts[m_current].models, last};
    }

private:
    struct Context {
        std::unique_ptr<Models> models; // null until the channel occurs
        std::vector<std::uint8_t> last;
    };

    void open(std::uint32_t channel, const std::uint8_t* from) {
        Context& context = m_contexts[channel];
        context.models = std::make_unique<Models>(m_itemBytes);
        context.last.assign(from, from + m_itemBytes);
    }

    std::size_t m_itemBytes;
    std::uint32_t m_version;
    std::uint32_t m_current = 0;
    std::array<Context, 4> m_contexts;
};

} // namespace omicron::laz
