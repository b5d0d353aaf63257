// LASzip's running median of five, as the decoder computes it without branches, against the
// insertion it is written after (kept here as the reference): the same five values after every
// step, for differences spread wide, clustered (many ties) and at the ends of the int32 range.
#include "io/laz/streaming_median.hpp"

#include <array>
#include <cstdint>
#include <gtest/gtest.h>
#include <limits>
#include <random>

namespace omicron::laz {
namespace {

// LASzip's insertion, branch by branch.
class ReferenceMedian5 {
public:
    std::int32_t median() const { return v[2]; }

    void add(std::int32_t value) {
        if (high) {
            if (value < v[2]) {
                v[4] = v[3];
                v[3] = v[2];
                if (value < v[0]) {
                    v[2] = v[1];
                    v[1] = v[0];
                    v[0] = value;
                } else if (value < v[1]) {
                    v[2] = v[1];
                    v[1] = value;
                } else {
                    v[2] = value;
                }
            } else {
                if (value < v[3]) {
                    v[4] = v[3];
                    v[3] = value;
                } else {
                    v[4] = value;
                }
                high = false;
            }
        } else {
            if (v[2] < value) {
                v[0] = v[1];
                v[1] = v[2];
                if (v[4] < value) {
                    v[2] = v[3];
                    v[3] = v[4];
                    v[4] = value;
                } else if (v[3] < value) {
                    v[2] = v[3];
                    v[3] = value;
                } else {
                    v[2] = value;
                }
            } else {
                if (v[1] < value) {
                    v[0] = v[1];
                    v[1] = value;
                } else {
                    v[0] = value;
                }
                high = true;
            }
        }
    }

    std::array<std::int32_t, 5> v{};
    bool high = true;
};

template <typename Draw> void expectSameMedians(Draw draw, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    StreamingMedian5 median;
    ReferenceMedian5 reference;
    for (int i = 0; i < 200000; ++i) {
        const std::int32_t value = draw(random);
        median.add(value);
        reference.add(value);
        ASSERT_EQ(median.median(), reference.median()) << "after " << i + 1 << " values";
        ASSERT_EQ(median.values(), reference.v) << "after " << i + 1 << " values";
    }
}

TEST(StreamingMedian5, MatchesLaszipsInsertionOnWideDifferences) {
    expectSameMedians(
        [](std::mt19937_64& r) {
            return std::uniform_int_distribution<std::int32_t>(-100000, 100000)(r);
        },
        1);
}

TEST(StreamingMedian5, MatchesLaszipsInsertionWithManyTies) {
    expectSameMedians(
        [](std::mt19937_64& r) { return std::uniform_int_distribution<std::int32_t>(-2, 2)(r); },
        2);
}

TEST(StreamingMedian5, MatchesLaszipsInsertionAtTheEndsOfTheRange) {
    expectSameMedians(
        [](std::mt19937_64& r) {
            constexpr std::array<std::int32_t, 5> ends{std::numeric_limits<std::int32_t>::min(),
                                                       std::numeric_limits<std::int32_t>::min() + 1,
                                                       0,
                                                       std::numeric_limits<std::int32_t>::max() - 1,
                                                       std::numeric_limits<std::int32_t>::max()};
            return ends[std::uniform_int_distribution<std::size_t>(0, ends.size() - 1)(r)];
        },
        3);
}

} // namespace
} // namespace omicron::laz
