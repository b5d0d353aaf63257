// Level-21 Morton codes of many unit-cube positions at once: the read phase codes every point
// of the cloud, on the reader's thread, beside the parse.
//
// Bit for bit morton::encodeUnit of each position. One point at a time the byte table of
// morton.hpp is the fastest spread; over a batch the shift-and-mask spread runs on vector
// lanes instead, compiled for AVX-512 and AVX2 too and picked on first use (on a CPU without
// them, the baseline x86-64 build of the same loop runs).
#pragma once

#include "points/morton.hpp"

#include <glm/vec3.hpp>
#include <span>
#include <vector>

namespace omicron::morton {

// codes[i] = encodeUnit(positions[i]) for every i; the spans have the same size (asserted).
void encodeUnitBatch(std::span<const glm::vec3> positions, std::span<Code> codes);

namespace detail {
// A compiled variant of the batch encoder: baseline x86-64 (SSE2), AVX2, AVX-512.
struct BatchEncoderVariant {
    const char* name;
    void (*encode)(std::span<const glm::vec3> positions, std::span<Code> codes);
};
// Every variant this CPU can run, the baseline first (tests compare them all).
std::vector<BatchEncoderVariant> batchEncoders();
} // namespace detail

} // namespace omicron::morton
