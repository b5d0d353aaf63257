// Colour modes shared by the point and splat vertex shaders (prepended after #version).
// Keep the numbers in sync with ColorMode in src/widget/render_settings.hpp.
const int kColorRgb = 0;
const int kColorNormal = 1;
const int kColorHeight = 2;
const int kColorIntensity = 3;
const int kColorLevel = 4;
const int kColorBuildAge = 5;
const int kColorClassification = 6;
const int kColorReturnNumber = 7;
const int kColorGpsTime = 8;

uniform int u_colorMode;
uniform vec2 u_heightRange;   // z of the cloud's lowest and highest point (unit cube)
uniform vec3 u_levelColor;    // the node's level, from the palette (level mode)
uniform float u_buildAge;     // 0 = built first, 1 = built last (build-age mode)
// The 256 ASPRS class colours (lasClassColor, RGBA8 with red lowest): uniforms rather than a
// texture, so the vertex and compute shaders need no sampler unit of their own (256 of the
// 1024 components GL 3.3 guarantees a vertex shader, of the 512 GL 4.3 guarantees compute).
uniform uint u_classColors[256];
// Hidden classes, one bit each (class c: bit c % 32 of word c / 32); u_classFilter is false
// when none is hidden, so the usual frame reads no LAS byte for it.
uniform bool u_classFilter;
uniform uint u_hiddenClasses[8];
uniform vec2 u_gpsTimeRange; // lowest and highest GPS time uploaded (relative to the base)

// RGBA8 (red lowest) to rgb; unpackUnorm4x8 needs GLSL 4.00, the vertex shaders are 3.30.
vec3 unpackRgb8(uint bits) {
    return vec3(uvec3(bits, bits >> 8u, bits >> 16u) & 0xffu) / 255.0;
}

bool classHidden(uint classification) {
    return u_classFilter &&
           ((u_hiddenClasses[classification >> 5u] >> (classification & 31u)) & 1u) != 0u;
}

// A perceptual ramp (viridis-like, from dark blue through green to yellow).
vec3 ramp(float t) {
    t = clamp(t, 0.0, 1.0);
    vec3 c0 = vec3(0.267, 0.005, 0.329);
    vec3 c1 = vec3(0.128, 0.567, 0.551);
    vec3 c2 = vec3(0.993, 0.906, 0.144);
    return t < 0.5 ? mix(c0, c1, t * 2.0) : mix(c1, c2, t * 2.0 - 1.0);
}

// A diverging ramp for the build sweep: cold = early, hot = recent.
vec3 ageRamp(float t) {
    t = clamp(t, 0.0, 1.0);
    vec3 early = vec3(0.230, 0.299, 0.754);
    vec3 mid = vec3(0.865, 0.865, 0.865);
    vec3 late = vec3(0.706, 0.016, 0.150);
    return t < 0.5 ? mix(early, mid, t * 2.0) : mix(mid, late, t * 2.0 - 1.0);
}

// The return-number colours: 1st, 2nd, 3rd, 4th and later; grey where unknown (0).
vec3 returnColor(uint returnNumber) {
    if (returnNumber == 0u) {
        return vec3(0.6);
    }
    if (returnNumber == 1u) {
        return vec3(1.0, 0.78, 0.2);
    }
    if (returnNumber == 2u) {
        return vec3(0.2, 0.8, 0.45);
    }
    if (returnNumber == 3u) {
        return vec3(0.25, 0.45, 1.0);
    }
    return vec3(0.85, 0.3, 0.85);
}

// The colour of a point in the current mode; the compute rasterizer passes the node's level
// colour and build age itself (one dispatch draws many nodes), the vertex shaders the uniforms.
// las: classification, return number, number of returns, flags.
vec3 pointColorOf(vec3 position, vec4 color, vec3 normal, uvec4 las, float gpsTime,
                  vec3 levelColor, float buildAge) {
    if (u_colorMode == kColorNormal) {
        return length(normal) > 0.0 ? normalize(normal) * 0.5 + 0.5 : vec3(0.6);
    }
    if (u_colorMode == kColorHeight) {
        float range = max(u_heightRange.y - u_heightRange.x, 1e-9);
        return ramp((position.z - u_heightRange.x) / range);
    }
    if (u_colorMode == kColorIntensity) {
        return vec3(color.a);
    }
    if (u_colorMode == kColorLevel) {
        return levelColor;
    }
    if (u_colorMode == kColorBuildAge) {
        return ageRamp(buildAge);
    }
    if (u_colorMode == kColorClassification) {
        return unpackRgb8(u_classColors[las.x]);
    }
    if (u_colorMode == kColorReturnNumber) {
        return returnColor(las.y);
    }
    if (u_colorMode == kColorGpsTime) {
        float span = max(u_gpsTimeRange.y - u_gpsTimeRange.x, 1e-9);
        return ramp((gpsTime - u_gpsTimeRange.x) / span);
    }
    return color.rgb;
}

vec3 pointColor(vec3 position, vec4 color, vec3 normal, uvec4 las, float gpsTime) {
    return pointColorOf(position, color, normal, las, gpsTime, u_levelColor, u_buildAge);
}
