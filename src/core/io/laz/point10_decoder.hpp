// The POINT10 item, version 2: the 20 bytes every LAS 1.0-1.3 point record starts with (x, y,
// z, intensity, return bits, classification, scan angle rank, user data, point source ID).
// A bit mask says which non-coordinate fields changed since the last point; x and y are coded
// as differences predicted by the median of recent differences, z from the last z, each in a
// context of the point's return number and number of returns.
#pragma once

#include "io/laz/integer_decoder.hpp"
#include "io/laz/pointwise_item_decoder.hpp"
#include "io/laz/streaming_median.hpp"

#include <array>
#include <memory>

namespace omicron::laz {

inline constexpr std::size_t kPoint10Bytes = 20;

class Point10Decoder final : public PointwiseItemDecoder {
public:
    Point10Decoder();

    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    // The last point's fields; `returnBits` is the record's byte 14 (return number in bits
    // 0-2, number of returns in bits 3-5, scan direction bit 6, edge of flight line bit 7).
    struct Fields {
        std::int32_t x = 0, y = 0, z = 0;
        std::uint16_t intensity = 0;
        std::uint8_t returnBits = 0;
        std::uint8_t classification = 0;
        std::uint8_t scanAngleRank = 0;
        std::uint8_t userData = 0;
        std::uint16_t pointSourceId = 0;
    };

    // A model per previous byte value, made on first use (LASzip makes them lazily too: a
    // fresh model is the encoder's starting state either way).
    using ModelPerByte = std::array<std::unique_ptr<SymbolModel>, 256>;
    static SymbolModel& modelFor(ModelPerByte& models, std::uint8_t previous);

    Fields m_last;
    std::array<std::uint16_t, 16> m_lastIntensity{};
    std::array<StreamingMedian5, 16> m_xDiffMedian;
    std::array<StreamingMedian5, 16> m_yDiffMedian;
    std::array<std::int32_t, 8> m_lastHeight{};

    SymbolModel m_changedValues{64};
    std::array<SymbolModel, 2> m_scanAngleRank{SymbolModel(256), SymbolModel(256)};
    ModelPerByte m_returnBits;
    ModelPerByte m_classification;
    ModelPerByte m_userData;
    IntegerDecoder m_intensity{16, 4};
    IntegerDecoder m_pointSourceId{16};
    IntegerDecoder m_dx{32, 2};
    IntegerDecoder m_dy{32, 22};
    IntegerDecoder m_z{32, 20};
};

} // namespace omicron::laz
