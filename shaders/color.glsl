// Colour modes shared by the point and splat vertex shaders (prepended after #version).
// Keep the numbers in sync with ColorMode in src/widget/render_settings.hpp.
const int kColorRgb = 0;
const int kColorNormal = 1;
const int kColorHeight = 2;
const int kColorIntensity = 3;
const int kColorLevel = 4;
const int kColorBuildAge = 5;

uniform int u_colorMode;
uniform vec2 u_heightRange;   // z of the cloud's lowest and highest point (unit cube)
uniform vec3 u_levelColor;    // the node's level, from the palette (level mode)
uniform float u_buildAge;     // 0 = built first, 1 = built last (build-age mode)

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

// The colour of a point in the current mode; the compute rasterizer passes the node's level
// colour and build age itself (one dispatch draws many nodes), the vertex shaders the uniforms.
vec3 pointColorOf(vec3 position, vec4 color, vec3 normal, vec3 levelColor, float buildAge) {
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
    return color.rgb;
}

vec3 pointColor(vec3 position, vec4 color, vec3 normal) {
    return pointColorOf(position, color, normal, u_levelColor, u_buildAge);
}
