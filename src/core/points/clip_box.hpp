// An oriented box the viewer clips the cloud to: a centre, half extents and a turn about the
// vertical (z) axis, as a scan operator places a box around a building or a thin slab as a
// section plane (huge along the plane, its thickness across). In whatever coordinates its
// user works in (source units in the viewer's settings, the unit cube for the front and the
// shaders: toUnitCube converts).
#pragma once

#include "points/cube_transform.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace omicron {

struct ClipBox {
    glm::dvec3 center{0.0};
    glm::dvec3 halfSize{1.0}; // > 0 on every axis
    double yawRadians = 0.0;  // the box's x axis turned this much from +x towards +y

    // `p` in the box's frame, each axis scaled so the box is [-1, 1]^3.
    glm::dvec3 toBox(const glm::dvec3& p) const;
    bool contains(const glm::dvec3& p) const;
    // Conservative: false only when the axis-aligned box [min, min + edge] lies wholly
    // outside (separated along one of the two boxes' face normals).
    bool intersects(const glm::dvec3& min, double edge) const;
    // The matrix of toBox, for shaders (single precision: unit-cube coordinates).
    glm::mat4 toBoxMatrix() const;

    friend bool operator==(const ClipBox&, const ClipBox&) = default;
};

// `box` (in source units) in the unit cube of `cube`.
ClipBox toUnitCube(const ClipBox& box, const CubeTransform& cube);

} // namespace omicron
