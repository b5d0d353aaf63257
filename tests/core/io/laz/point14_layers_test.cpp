// The POINT14 decoder, a layer at a time over a slice of points, against the point-at-a-time
// reference it replaced (reference_point14_decoder): the same records from the same bytes.
// Random layer bytes decode to random but deterministic points whose change masks switch
// scanner channels often, so every channel's context opening from the point before (which the
// real single-channel files never exercise) is compared, with layers of 0 bytes among them
// and with the points decoded in slices of every size.
#include "io/laz/point14_decoder.hpp"
#include "reference_point14_decoder.hpp"

#include <algorithm>
#include <cstring>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace omicron::laz {
namespace {

constexpr std::size_t kPoints = 3000;

struct Streams {
    std::vector<std::uint8_t> first = std::vector<std::uint8_t>(kPoint14Bytes);
    std::vector<std::vector<std::uint8_t>> layers{kPoint14Layers};
};

// Random bytes for the first item and each layer; layer k (k > 0) empty where bit k of
// `emptyLayers` is set.
Streams randomStreams(std::uint64_t seed, unsigned emptyLayers) {
    std::mt19937_64 random(seed);
    Streams s;
    for (std::uint8_t& byte : s.first) {
        byte = static_cast<std::uint8_t>(random());
    }
    for (std::size_t k = 0; k < kPoint14Layers; ++k) {
        if (k > 0 && (emptyLayers >> k) & 1u) {
            continue;
        }
        s.layers[k].resize(64 * 1024);
        for (std::uint8_t& byte : s.layers[k]) {
            byte = static_cast<std::uint8_t>(random());
        }
    }
    return s;
}

std::vector<Layer> startLayers(const Streams& s) {
    std::vector<Layer> layers(kPoint14Layers);
    for (std::size_t k = 0; k < kPoint14Layers; ++k) {
        if (!s.layers[k].empty()) {
            layers[k].present = true;
            layers[k].decoder.start(s.layers[k].data(), s.layers[k].data() + s.layers[k].size());
        }
    }
    return layers;
}

std::vector<std::uint8_t> referenceRecords(const Streams& s) {
    std::vector<Layer> layers = startLayers(s);
    test::ReferencePoint14Decoder decoder;
    decoder.start(s.first.data(), Point14Decoder::channelOf(s.first.data()), layers);
    std::vector<std::uint8_t> records(kPoints * kPoint14Bytes);
    for (std::size_t p = 0; p < kPoints; ++p) {
        decoder.decode(records.data() + p * kPoint14Bytes);
    }
    return records;
}

// The records decoded in slices of `slice` points (records `stride` bytes apart, as inside LAS
// records with more items after POINT14), and the channels the decoder reported.
std::vector<std::uint8_t> layeredRecords(const Streams& s, std::size_t slice,
                                         std::vector<std::uint8_t>& channels) {
    constexpr std::size_t stride = kPoint14Bytes + 7;
    std::vector<Layer> layers = startLayers(s);
    Point14Decoder decoder;
    decoder.start(s.first.data(), Point14Decoder::channelOf(s.first.data()), layers);
    std::vector<std::uint8_t> strided(kPoints * stride);
    channels.assign(kPoints, 0);
    for (std::size_t begin = 0; begin < kPoints; begin += slice) {
        const std::size_t count = std::min(slice, kPoints - begin);
        decoder.decode(strided.data() + begin * stride, count, stride, channels.data() + begin);
    }
    std::vector<std::uint8_t> records(kPoints * kPoint14Bytes);
    for (std::size_t p = 0; p < kPoints; ++p) {
        std::memcpy(records.data() + p * kPoint14Bytes, strided.data() + p * stride, kPoint14Bytes);
    }
    return records;
}

TEST(Point14Layers, SameRecordsAsThePointAtATimeReference) {
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
        // No empty layer, then a different set of empty layers for each seed.
        const unsigned emptyLayers =
            seed == 1 ? 0u : static_cast<unsigned>(seed * 0x9e37u) & 0x1feu;
        SCOPED_TRACE("seed " + std::to_string(seed) + ", empty layers " +
                     std::to_string(emptyLayers));
        const Streams streams = randomStreams(seed, emptyLayers);
        const std::vector<std::uint8_t> expected = referenceRecords(streams);
        std::array<bool, 4> channelSeen{};
        std::size_t switches = 0;
        for (const std::size_t slice :
             {kPoints, std::size_t{1}, std::size_t{7}, std::size_t{500}}) {
            std::vector<std::uint8_t> channels;
            const std::vector<std::uint8_t> got = layeredRecords(streams, slice, channels);
            for (std::size_t p = 0; p < kPoints; ++p) {
                ASSERT_EQ(std::memcmp(got.data() + p * kPoint14Bytes,
                                      expected.data() + p * kPoint14Bytes, kPoint14Bytes),
                          0)
                    << "point " << p << ", slices of " << slice;
                ASSERT_EQ(channels[p], Point14Decoder::channelOf(got.data() + p * kPoint14Bytes));
                channelSeen[channels[p]] = true;
                switches += p > 0 && channels[p] != channels[p - 1] ? 1 : 0;
            }
        }
        // The streams exercise what they are for: every channel, and many switches.
        EXPECT_TRUE(std::all_of(channelSeen.begin(), channelSeen.end(), [](bool b) { return b; }));
        EXPECT_GT(switches, 100u);
    }
}

} // namespace
} // namespace omicron::laz
