// Axis-aligned bounding boxes in source units (double: georeferenced coordinates need it).
#pragma once

#include <glm/vec3.hpp>
#include <glm/common.hpp>
#include <limits>

namespace omicron {

struct Bounds {
    glm::dvec3 min{std::numeric_limits<double>::infinity()};
    glm::dvec3 max{-std::numeric_limits<double>::infinity()};

    bool empty() const { return !(min.x <= max.x && min.y <= max.y && min.z <= max.z); }
    void extend(const glm::dvec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void extend(const Bounds& other) {
        if (!other.empty()) {
            extend(other.min);
            extend(other.max);
        }
    }
    glm::dvec3 extent() const { return empty() ? glm::dvec3(0.0) : max - min; }
    bool contains(const glm::dvec3& p, double tolerance = 0.0) const {
        return p.x >= min.x - tolerance && p.y >= min.y - tolerance && p.z >= min.z - tolerance &&
               p.x <= max.x + tolerance && p.y <= max.y + tolerance && p.z <= max.z + tolerance;
    }
    friend bool operator==(const Bounds&, const Bounds&) = default;
};

} // namespace omicron
