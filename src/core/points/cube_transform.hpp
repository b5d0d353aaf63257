// The paper's normalisation: source coordinates -> the unit cube [0,1]^3 and back.
//
// origin = bounding-box min corner, edge = the largest extent, so the longest axis spans
// [0, 1] exactly and the others [0, extent/edge]. Kept in double so that georeferenced data
// (coordinates of 10^6 with centimetre steps) round-trips: positions in the unit cube are
// float (2^-24 resolution, finer than the 2^-21 cells of the deepest Morton level).
#pragma once

#include "points/bounds.hpp"

#include <algorithm>
#include <glm/vec3.hpp>

namespace omicron {

struct CubeTransform {
    glm::dvec3 origin{0.0};
    double edge = 1.0; // always > 0

    // A degenerate cloud (one point, or all points equal) gets edge 1 so that nothing divides
    // by zero; every point then sits at the cube's origin.
    static CubeTransform fromBounds(const Bounds& bounds) {
        if (bounds.empty()) {
            return {};
        }
        const glm::dvec3 e = bounds.extent();
        const double largest = std::max({e.x, e.y, e.z});
        return {bounds.min, largest > 0.0 ? largest : 1.0};
    }

    glm::vec3 toUnit(const glm::dvec3& source) const {
        return glm::vec3((source - origin) / edge);
    }
    glm::dvec3 toSource(const glm::vec3& unit) const {
        return origin + glm::dvec3(unit) * edge;
    }
    friend bool operator==(const CubeTransform&, const CubeTransform&) = default;
};

} // namespace omicron
