// The render parameters the build panel edits next to the build's: the front's projection
// threshold, the per-frame point budget, the render mode and eye-dome lighting. The main window maps them onto
// CloudView's RenderSettings, so the panel needs no GL header (render_settings.hpp has none).
#pragma once

#include "render_settings.hpp"

#include <cstddef>

namespace omicron {

struct ViewParameters {
    // The same defaults as the viewer's RenderSettings (see render_settings.hpp for why).
    double projectionThresholdPx = 16.0;           // front: branch above, prune below
    std::size_t pointBudget = 1'000'000;           // most points drawn per frame
    RenderMode renderMode = RenderSettings{}.mode; // points, compute points or surface splats
    EdlMode edl = RenderSettings{}.edl;            // eye-dome lighting
    float edlStrength = RenderSettings{}.edlStrength;
    float edlRadiusPx = RenderSettings{}.edlRadiusPx;
    friend bool operator==(const ViewParameters&, const ViewParameters&) = default;
};

} // namespace omicron
