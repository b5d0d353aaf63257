#include "points/morton_batch.hpp"

#include <cassert>
#include <cstdint>

namespace omicron::morton {

namespace {

// The low 21 bits of v with bit i moved to bit 3*i: five shift-and-mask steps, each a few
// vector instructions over 64-bit lanes (where the byte table would need gathers).
inline Code spreadBits3Shifts(std::uint32_t v) {
    Code x = v & 0x1fffffu;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

// quantize() through a signed conversion, which every vector width has: the clamped value is
// in [0, 2^21 - 1], where it truncates the same.
inline std::uint32_t quantizeLane(float unit) {
    const float scaled = unit * static_cast<float>(kCellsPerAxis);
    const float positive = scaled > 0.0f ? scaled : 0.0f; // NaN compares false -> 0
    const float lastCell = static_cast<float>(kCellsPerAxis - 1);
    return static_cast<std::uint32_t>(
        static_cast<std::int32_t>(positive < lastCell ? positive : lastCell));
}

// Written once, compiled into each entry point below (the loop is inlined into each, so each
// gets the vector width of its target).
[[gnu::always_inline]] inline void encodeLoop(std::span<const glm::vec3> positions,
                                              std::span<Code> codes) {
    assert(positions.size() == codes.size());
    const float* xyz = &positions.data()->x;
    Code* out = codes.data();
    const std::size_t count = positions.size();
    for (std::size_t i = 0; i < count; ++i) {
        const Code x = spreadBits3Shifts(quantizeLane(xyz[3 * i]));
        const Code y = spreadBits3Shifts(quantizeLane(xyz[3 * i + 1]));
        const Code z = spreadBits3Shifts(quantizeLane(xyz[3 * i + 2]));
        out[i] = (Code{1} << (3 * kMaxLevel)) | x | y << 1 | z << 2;
    }
}

using BatchEncoder = void (*)(std::span<const glm::vec3>, std::span<Code>);

void encodeBaseline(std::span<const glm::vec3> positions, std::span<Code> codes) {
    encodeLoop(positions, codes);
}

#if defined(__x86_64__) && defined(__GNUC__)
[[gnu::target("avx512f,avx512dq,avx512bw,avx512vl")]] void
encodeAvx512(std::span<const glm::vec3> positions, std::span<Code> codes) {
    encodeLoop(positions, codes);
}

[[gnu::target("avx2")]] void encodeAvx2(std::span<const glm::vec3> positions,
                                        std::span<Code> codes) {
    encodeLoop(positions, codes);
}
#endif

} // namespace

std::vector<detail::BatchEncoderVariant> detail::batchEncoders() {
    std::vector<BatchEncoderVariant> variants{{"baseline", &encodeBaseline}};
#if defined(__x86_64__) && defined(__GNUC__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2")) {
        variants.push_back({"avx2", &encodeAvx2});
    }
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl")) {
        variants.push_back({"avx512", &encodeAvx512});
    }
#endif
    return variants;
}

// The widest variant, chosen on first use. Not an ifunc (target_clones): its resolver runs
// while the dynamic loader relocates, before a sanitizer's runtime is up, and crashed the TSan
// build.
void encodeUnitBatch(std::span<const glm::vec3> positions, std::span<Code> codes) {
    static const BatchEncoder encode = detail::batchEncoders().back().encode;
    encode(positions, codes);
}

} // namespace omicron::morton
