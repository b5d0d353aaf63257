#include "front/front_projection.hpp"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <limits>

namespace omicron {

CellBox cellBox(morton::Code code) {
    const int level = morton::level(code);
    const morton::Cell cell = morton::decode(code);
    // Exact in double: the edge is a power of two, the cell indices have at most 21 bits.
    const double edge = std::ldexp(1.0, -level);
    return {glm::dvec3(cell.x, cell.y, cell.z) * edge, edge};
}

FrustumPlanes frustumPlanes(const glm::dmat4& m) {
    // Gribb & Hartmann: row i of the matrix (GLM is column-major, m[column][row]).
    const auto row = [&](int i) { return glm::dvec4(m[0][i], m[1][i], m[2][i], m[3][i]); };
    const glm::dvec4 r0 = row(0), r1 = row(1), r2 = row(2), r3 = row(3);
    return {{r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2}, std::nullopt};
}

bool intersectsFrustum(const FrustumPlanes& frustum, const CellBox& box) {
    for (const glm::dvec4& plane : frustum.planes) {
        // The box corner furthest along the plane's normal: if even it is outside, all are.
        const glm::dvec3 corner(plane.x >= 0.0 ? box.min.x + box.edge : box.min.x,
                                plane.y >= 0.0 ? box.min.y + box.edge : box.min.y,
                                plane.z >= 0.0 ? box.min.z + box.edge : box.min.z);
        if (plane.x * corner.x + plane.y * corner.y + plane.z * corner.z + plane.w < 0.0) {
            return false;
        }
    }
    return !frustum.clip || frustum.clip->intersects(box.min, box.edge);
}

double projectedSizePx(const CellBox& box, const FrontCamera& camera) {
    const double diagonal = box.diagonal();
    if (camera.orthographic) {
        return diagonal * camera.pixelsPerUnitAtUnitDistance;
    }
    const double distance = glm::length(box.center() - camera.eye);
    // Inside (or touching) the cell's bounding sphere: it fills the view.
    if (distance <= 0.5 * diagonal) {
        return std::numeric_limits<double>::infinity();
    }
    return diagonal / distance * camera.pixelsPerUnitAtUnitDistance;
}

FrontCamera perspectiveCamera(const glm::dvec3& eye, const glm::dvec3& target,
                              double fovYRadians, double aspect, double viewportHeightPx) {
    const glm::dvec3 forward = glm::normalize(target - eye);
    const glm::dvec3 up = std::abs(forward.z) > 0.999 ? glm::dvec3(0.0, 1.0, 0.0)
                                                      : glm::dvec3(0.0, 0.0, 1.0);
    // The unit cube is within sqrt(3) of any point in it: near and far enclose it from any
    // eye closer than a few cube edges, with near small enough for an eye inside.
    const double far = glm::length(eye - glm::dvec3(0.5)) + 1.0;
    const double near = std::max(1e-4, far * 1e-5);
    FrontCamera camera;
    camera.viewProjection = glm::perspective(fovYRadians, aspect, near, far) *
                            glm::lookAt(eye, target, up);
    camera.eye = eye;
    camera.pixelsPerUnitAtUnitDistance = viewportHeightPx / (2.0 * std::tan(0.5 * fovYRadians));
    camera.orthographic = false;
    return camera;
}

} // namespace omicron
