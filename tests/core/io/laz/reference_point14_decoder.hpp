// The POINT14 decoder as it was before it decoded a layer at a time: every layer of one point,
// then the next point. Kept as the reference of a differential test (point14_layers_test.cpp):
// the real files at hand have one scanner channel, so only streams of random bytes (which
// switch channels often) check the layer-at-a-time decoder's channel contexts against it.
#pragma once

#include "io/laz/gpstime_decoder.hpp"
#include "io/laz/layered_item_decoder.hpp"
#include "io/laz/streaming_median.hpp"

#include <array>
#include <memory>
#include <span>

namespace omicron::laz::test {

class ReferencePoint14Decoder {
public:
    ReferencePoint14Decoder();
    ~ReferencePoint14Decoder();

    void start(const std::uint8_t* firstItem, std::uint32_t channel, std::span<Layer> layers);
    void decode(std::uint8_t* item);

private:
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
        void store(std::uint8_t* item) const;
    };
    struct Context;

    Context& open(std::uint32_t channel, const Fields& from);

    std::span<Layer> m_layers;
    std::array<std::unique_ptr<Context>, 4> m_contexts;
    std::uint32_t m_current = 0;
};

} // namespace omicron::laz::test
