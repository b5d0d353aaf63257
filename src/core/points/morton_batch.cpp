#include "points/morton_batch.hpp"

#include <cassert>
#include <cstdint>

namespace omicron::morton {

namespace {

// Written once, compiled into each entry point below (the loop is inlined into each, so each
// gets the vector width of its target).
[[gnu::always_inline]] inline void encodeLoop(std::span<const glm::vec3> positions,
                                              std::span<Code> codes) {
    assert(positions.size() == codes.size());
    const float* xyz = &positions.data()->x;
    Code* out = codes.data();
    const std::size_t count = positions.size();
    for (std::size_t i = 0; i < count; ++i) {
        const Code x = detail::spreadBits3Shifts(quantize(xyz[3 * i]));
        const Code y = detail::spreadBits3Shifts(quantize(xyz[3 * i + 1]));
        const Code z = detail::spreadBits3Shifts(quantize(xyz[3 * i + 2]));
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
