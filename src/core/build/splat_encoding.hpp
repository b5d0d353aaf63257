// Compact encodings of the splat attributes: what a saved hierarchy stores per point and what
// the estimator produces (so a loaded file and a fresh estimate are the same bytes).
//
// Radius: 16 bits, log2-encoded in 1/2048-octave steps over 2^-32..1 (unit-cube units).
// Normal: octahedral, 2 x 16-bit signed normalised (x in the low half).
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

namespace omicron {

// Octahedral encoding of a direction in 2 x 16 bits (x in the low half): of `normal`
// divided by its L1 norm, so any non-zero length will do.
std::uint32_t encodeOctahedral(const glm::vec3& normal);
glm::vec3 decodeOctahedral(std::uint32_t encoded);
// Stored where no normal could be estimated (fewer than 3 points, or all on a line); decodes
// to (0, 0, 0): the renderer draws a screen-aligned splat there.
inline constexpr std::uint32_t kUnknownNormal = 0x80008000u;

std::uint16_t encodeRadius(float radius);
float decodeRadius(std::uint16_t encoded);

} // namespace omicron
