// The point-wise items of LASzip 1.x (item version 1): POINT10, GPSTIME11, RGB12 and BYTE as
// the first LAZ files coded them (LAZ 1.0 to 1.2, still found in archives and test suites).
// Same arithmetic coder, models and integer decoder as version 2, simpler predictions:
// - POINT10: x and y differences predicted by the median of the last three, z by the last z,
//   all before the change mask; the other fields from their last value, with no return
//   contexts;
// - GPSTIME11: one sequence of times, coded as a multiple of the last 32-bit difference;
// - RGB12: each of the six colour bytes from the same byte of the last point;
// - BYTE: every extra byte coded, each in its own context.
#pragma once

#include "io/laz/integer_decoder.hpp"
#include "io/laz/pointwise_item_decoder.hpp"

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

namespace omicron::laz {

class Point10V1Decoder final : public PointwiseItemDecoder {
public:
    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    using ModelPerByte = std::array<std::unique_ptr<SymbolModel>, 256>;
    static SymbolModel& modelFor(ModelPerByte& models, std::uint8_t previous);

    std::array<std::uint8_t, 20> m_last{}; // the last record's 20 bytes, as stored
    std::array<std::int32_t, 3> m_xDiff{};
    std::array<std::int32_t, 3> m_yDiff{};
    std::size_t m_next = 0; // the oldest difference, replaced next

    IntegerDecoder m_dx{32, 1};
    IntegerDecoder m_dy{32, 20};
    IntegerDecoder m_z{32, 20};
    IntegerDecoder m_intensity{16, 1};
    IntegerDecoder m_scanAngleRank{8, 2};
    IntegerDecoder m_pointSourceId{16, 1};
    SymbolModel m_changedValues{64};
    ModelPerByte m_returnBits;
    ModelPerByte m_classification;
    ModelPerByte m_userData;
};

class GpsTime11V1Decoder final : public PointwiseItemDecoder {
public:
    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    std::uint64_t m_lastTime = 0; // the double's bits
    std::int32_t m_lastDifference = 0;
    std::int32_t m_extremeCounter = 0;
    SymbolModel m_multiplier{512};
    SymbolModel m_zeroDifference{3}; // used while the last difference is 0
    IntegerDecoder m_integer{32, 6};
};

class Rgb12V1Decoder final : public PointwiseItemDecoder {
public:
    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    std::array<std::uint8_t, 6> m_last{}; // red low, red high, green low, ..., blue high
    SymbolModel m_changedBytes{64};
    IntegerDecoder m_byte{8, 6};
};

class ByteV1Decoder final : public PointwiseItemDecoder {
public:
    explicit ByteV1Decoder(std::size_t byteCount);

    void start(const std::uint8_t* item) override;
    void decode(ArithmeticDecoder& decoder, std::uint8_t* item) override;

private:
    std::vector<std::uint8_t> m_last;
    IntegerDecoder m_byte;
};

} // namespace omicron::laz
