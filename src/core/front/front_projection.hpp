// What the front asks of the camera about one octree cell: is it in the view frustum, and how
// many pixels does it cover. Cells are the hierarchy's unit-cube cells (morton::decode and the
// level give them), so no node has to be read.
#pragma once

#include "front/front.hpp"
#include "points/clip_box.hpp"
#include "points/morton.hpp"

#include <array>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <optional>

namespace omicron {

struct CellBox {
    glm::dvec3 min{0.0};
    double edge = 1.0;
    glm::dvec3 center() const { return min + glm::dvec3(0.5 * edge); }
    double diagonal() const { return edge * 1.7320508075688772; } // edge * sqrt(3)
};

// The cell of `code` in the unit cube.
CellBox cellBox(morton::Code code);

// The six planes of a view-projection matrix (OpenGL clip space, -w <= x, y, z <= w), each as
// (normal, offset): a point p is inside when dot(normal, p) + offset >= 0 for all six.
struct FrustumPlanes {
    std::array<glm::dvec4, 6> planes;
    // The camera's clip box (unit cube), if any: a cell wholly outside it is not visible
    // either, so clipped-away nodes cost neither drawing nor points of the budget.
    std::optional<ClipBox> clip;
};
FrustumPlanes frustumPlanes(const glm::dmat4& viewProjection);

// Conservative: true unless the whole box lies outside one plane (a box near a frustum corner
// may be kept; it costs a little drawing, never a hole) or outside the clip box.
bool intersectsFrustum(const FrustumPlanes& frustum, const CellBox& box);

// The cell's diagonal in pixels: diagonal / distance(eye, centre) * pixelsPerUnitAtUnitDistance
// (perspective; a cell around the eye is infinitely large), or diagonal * pixels per unit
// (orthographic).
double projectedSizePx(const CellBox& box, const FrontCamera& camera);

// A perspective camera at `eye` looking at `target` (unit-cube coordinates, +z up unless the
// view is vertical), as tests, benchmarks and a widget without its own matrices need it.
FrontCamera perspectiveCamera(const glm::dvec3& eye, const glm::dvec3& target,
                              double fovYRadians, double aspect, double viewportHeightPx);

} // namespace omicron
