// One item (POINT10, GPSTIME11, RGB12, BYTE) of a point-wise LAZ chunk, the compressor of point
// formats 0 to 5: a chunk stores its first point raw, then codes every item of every further
// point in turn on one arithmetic stream, each predicted from the same item of the point before.
#pragma once

#include "io/laz/arithmetic_decoder.hpp"

#include <cstdint>

namespace omicron::laz {

class PointwiseItemDecoder {
public:
    virtual ~PointwiseItemDecoder() = default;

    // The chunk's first point's item as stored raw: what the second point is predicted from.
    virtual void start(const std::uint8_t* item) = 0;

    // Decodes the next point's item into `item` (the item's size in bytes, a standard LAS
    // record's bytes for that item).
    virtual void decode(ArithmeticDecoder& decoder, std::uint8_t* item) = 0;
};

} // namespace omicron::laz
