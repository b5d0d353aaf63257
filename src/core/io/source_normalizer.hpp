// Converts source coordinates to the unit cube while reading, shared by all readers: skips
// non-finite points and rejects points outside the bounds the cube was built from.
#pragma once

#include "io/input_error.hpp"
#include "points/bounds.hpp"
#include "points/cube_transform.hpp"

#include <cmath>
#include <glm/vec3.hpp>
#include <string>

namespace omicron {

class SourceNormalizer {
public:
    // `quantumTolerance`: how far outside `bounds` a point may lie (e.g. half a LAS scale
    // step, or float rounding of a header's bounds) before it is an error.
    SourceNormalizer(const CubeTransform& cube, const Bounds& bounds, double quantumTolerance)
        : m_cube(cube), m_inverseEdge(1.0 / cube.edge), m_bounds(bounds),
          m_tolerance(quantumTolerance + 1e-9 * cube.edge) {}

    static bool isFinite(const glm::dvec3& p) {
        return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    }

    bool inBounds(const glm::dvec3& source) const { return m_bounds.contains(source, m_tolerance); }

    glm::vec3 toUnit(const glm::dvec3& source) const {
        return glm::vec3((source - m_cube.origin) * m_inverseEdge);
    }

    // Throws the OutOfBounds error for a finite point that failed inBounds().
    [[noreturn]] void throwOutOfBounds(const std::string& path, InputLocation where,
                                       const glm::dvec3& source) const;

private:
    CubeTransform m_cube;
    double m_inverseEdge;
    Bounds m_bounds;
    double m_tolerance;
};

} // namespace omicron
