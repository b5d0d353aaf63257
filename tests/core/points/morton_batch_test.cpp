// The batch Morton encoder is bit for bit morton::encodeUnit, in every compiled variant this
// CPU can run (baseline, AVX2, AVX-512), over vector tails and every value quantize() clamps.
#include "points/morton_batch.hpp"

#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <vector>

namespace omicron {
namespace {

using morton::Code;

// Values where quantize() clamps, rounds or meets a cell boundary.
std::vector<float> edgeValues() {
    const float inf = std::numeric_limits<float>::infinity();
    const float cells = static_cast<float>(morton::kCellsPerAxis);
    return {0.0f,
            -0.0f,
            1.0f,
            std::nextafter(1.0f, 0.0f),
            std::nextafter(1.0f, 2.0f),
            std::nextafter(0.0f, 1.0f), // the smallest denormal
            -std::numeric_limits<float>::min(),
            -1.0f,
            2.0f,
            1e30f,
            -1e30f,
            inf,
            -inf,
            std::numeric_limits<float>::quiet_NaN(),
            0.5f,
            1.0f / cells,
            std::nextafter(1.0f / cells, 0.0f),
            (cells - 1.0f) / cells,
            std::nextafter((cells - 1.0f) / cells, 0.0f)};
}

std::vector<glm::vec3> testPositions() {
    std::vector<glm::vec3> positions;
    const std::vector<float> edges = edgeValues();
    for (float x : edges) {
        for (float y : edges) {
            positions.emplace_back(x, y, edges[positions.size() % edges.size()]);
        }
    }
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int i = 0; i < 10'000; ++i) {
        positions.emplace_back(unit(random), unit(random), unit(random));
    }
    return positions;
}

using BatchEncoder = void (*)(std::span<const glm::vec3>, std::span<Code>);

void expectEqualsEncodeUnit(BatchEncoder encode) {
    const std::vector<glm::vec3> positions = testPositions();
    // Sizes around the vector widths, so every tail length is taken.
    for (std::size_t size :
         {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{7}, std::size_t{8},
          std::size_t{9}, std::size_t{15}, std::size_t{17}, positions.size()}) {
        for (std::size_t first : {std::size_t{0}, std::size_t{1}, std::size_t{5}}) {
            if (first + size > positions.size()) {
                continue;
            }
            const std::span<const glm::vec3> slice(positions.data() + first, size);
            std::vector<Code> codes(size + 1, 0xDEADull);
            encode(slice, std::span(codes).first(size));
            for (std::size_t i = 0; i < size; ++i) {
                const glm::vec3& p = slice[i];
                ASSERT_EQ(codes[i], morton::encodeUnit(p.x, p.y, p.z))
                    << "point " << first + i << " (" << p.x << ", " << p.y << ", " << p.z
                    << "), batch of " << size;
            }
            EXPECT_EQ(codes[size], 0xDEADull) << "wrote past the batch of " << size;
        }
    }
}

TEST(MortonBatch, EveryVariantThisCpuRunsEqualsEncodeUnit) {
    const auto variants = morton::detail::batchEncoders();
    ASSERT_FALSE(variants.empty());
    EXPECT_STREQ(variants.front().name, "baseline");
    for (const auto& variant : variants) {
        SCOPED_TRACE(variant.name);
        expectEqualsEncodeUnit(variant.encode);
    }
}

TEST(MortonBatch, TheEntryPointEqualsEncodeUnit) {
    expectEqualsEncodeUnit(&morton::encodeUnitBatch);
}

} // namespace
} // namespace omicron
