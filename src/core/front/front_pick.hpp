// Picking: which drawn point lies under the cursor. The renderer reads back the depth of the
// frame and unprojects it to a position in the unit cube; this finds the nearest point among
// those the front draws (the held points of its visible nodes near that position), so a pick
// names a real point of the cloud at whatever level of detail the view shows, also while a
// build runs (only published nodes are in a front) or while nodes are paged in (a front holds
// resident nodes only).
#pragma once

#include "build/hierarchy.hpp"
#include "front/front.hpp"

#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>
#include <span>

namespace omicron {

struct DrawnPoint {
    std::uint32_t cloudIndex = 0; // in the hierarchy's cloud
    morton::Code node = 0;        // the front node drawing it
    glm::vec3 unitPosition{0.0f};
    double distance = 0.0; // from the position asked for, unit-cube units
};

// The held point of a visible, non-placeholder entry of `entries` nearest to `unitPosition`,
// if one lies within `maxDistance`; only nodes whose cell comes that close are searched.
std::optional<DrawnPoint> nearestDrawnPoint(const Hierarchy& hierarchy,
                                            std::span<const FrontEntry> entries,
                                            const glm::dvec3& unitPosition, double maxDistance);

} // namespace omicron
