// The render parameters the build panel edits next to the build's: the front's projection
// threshold, the per-frame point budget and points vs splats. The main window maps them onto
// CloudView's RenderSettings, so the panel needs no GL header.
#pragma once

#include <cstddef>

namespace omicron {

struct ViewParameters {
    // The same defaults as the viewer's RenderSettings (see render_settings.hpp for why).
    double projectionThresholdPx = 16.0; // front: branch above, prune below
    std::size_t pointBudget = 1'000'000; // most points drawn per frame
    bool splats = false;                  // surface splats instead of GL points
    friend bool operator==(const ViewParameters&, const ViewParameters&) = default;
};

} // namespace omicron
