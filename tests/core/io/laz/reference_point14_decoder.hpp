// The POINT14 decoder as it was before it decoded a layer at a time: every layer of one point,
// then the next point. Kept as the reference of a differential test (point14_layers_test.cpp):
// the real files at hand have one scanner channel, so only streams of random bytes (which
// switch channels often) check the layer-at-a-time decoder's channel contexts against it. It
// shares the contexts and the first layer's step (io/laz/point14_context.hpp); the other
// layers are decoded here, point by point, from the context the first layer left.
#pragma once

#include "io/laz/layered_item_decoder.hpp"
#include "io/laz/point14_context.hpp"

#include <span>

namespace omicron::laz::test {

class ReferencePoint14Decoder {
public:
    void start(const std::uint8_t* firstItem, std::uint32_t channel, std::span<Layer> layers);
    void decode(std::uint8_t* item);

private:
    std::span<Layer> m_layers;
    point14::Contexts m_contexts;
};

} // namespace omicron::laz::test
