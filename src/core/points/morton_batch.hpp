// Level-21 Morton codes of many unit-cube positions at once: the read phase codes every point
// of the cloud, on the reader's thread, beside the parse.
//
// Bit for bit morton::encodeUnit of each position. One point at a time the byte table of
// morton.hpp is the fastest spread; over a batch the shift-and-mask spread runs on vector
// lanes instead, compiled for AVX-512 and AVX2 too and picked when the process starts (on a
// CPU without them, the baseline x86-64 build of the same loop runs).
#pragma once

#include "points/morton.hpp"

#include <glm/vec3.hpp>
#include <span>

namespace omicron::morton {

// codes[i] = encodeUnit(positions[i]) for every i; the spans have the same size (asserted).
void encodeUnitBatch(std::span<const glm::vec3> positions, std::span<Code> codes);

namespace detail {
// The same loop compiled for baseline x86-64 only (SSE2): what encodeUnitBatch runs on a CPU
// without AVX2; tests compare it too, whatever CPU runs them.
void encodeUnitBatchBaseline(std::span<const glm::vec3> positions, std::span<Code> codes);
} // namespace detail

} // namespace omicron::morton
