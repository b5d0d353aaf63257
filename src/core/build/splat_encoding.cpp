#include "build/splat_encoding.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

namespace omicron {

namespace {

constexpr double kRadiusStepsPerOctave = 2048.0;
constexpr double kRadiusMinExponent = -32.0; // code 0 = 2^-32; 65535 ~ 2^0

std::int16_t toSnorm16(float v) {
    const float scaled = std::clamp(v, -1.0f, 1.0f) * 32767.0f;
    return static_cast<std::int16_t>(scaled + (scaled < 0.0f ? -0.5f : 0.5f));
}

float signNotZero(float v) {
    return v < 0.0f ? -1.0f : 1.0f;
}

} // namespace

std::uint32_t encodeOctahedral(const glm::vec3& normal) {
    const float sum = std::abs(normal.x) + std::abs(normal.y) + std::abs(normal.z);
    if (!(sum > 0.0f)) {
        return kUnknownNormal;
    }
    const float inverse = 1.0f / sum;
    float x = normal.x * inverse, y = normal.y * inverse;
    if (normal.z < 0.0f) {
        const float fx = (1.0f - std::abs(y)) * signNotZero(x);
        const float fy = (1.0f - std::abs(x)) * signNotZero(y);
        x = fx;
        y = fy;
    }
    return static_cast<std::uint16_t>(toSnorm16(x)) |
           static_cast<std::uint32_t>(static_cast<std::uint16_t>(toSnorm16(y))) << 16;
}

glm::vec3 decodeOctahedral(std::uint32_t encoded) {
    if (encoded == kUnknownNormal) {
        return glm::vec3(0.0f);
    }
    const float x = static_cast<float>(static_cast<std::int16_t>(encoded & 0xffffu)) / 32767.0f;
    const float y = static_cast<float>(static_cast<std::int16_t>(encoded >> 16)) / 32767.0f;
    glm::vec3 v(x, y, 1.0f - std::abs(x) - std::abs(y));
    if (v.z < 0.0f) {
        const float fx = (1.0f - std::abs(y)) * signNotZero(x);
        const float fy = (1.0f - std::abs(x)) * signNotZero(y);
        v.x = fx;
        v.y = fy;
    }
    return glm::normalize(v);
}

std::uint16_t encodeRadius(float radius) {
    if (!(radius > 0.0f)) {
        return 0;
    }
    // float log2 is exact enough: one code step is 1/2048 octave.
    const float code = (std::log2(radius) - static_cast<float>(kRadiusMinExponent)) *
                       static_cast<float>(kRadiusStepsPerOctave);
    return static_cast<std::uint16_t>(std::clamp(code, 0.0f, 65535.0f) + 0.5f);
}

float decodeRadius(std::uint16_t encoded) {
    return static_cast<float>(
        std::exp2(static_cast<double>(encoded) / kRadiusStepsPerOctave + kRadiusMinExponent));
}

} // namespace omicron
