#include "points/clip_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace omicron {

glm::dvec3 ClipBox::toBox(const glm::dvec3& p) const {
    const glm::dvec3 d = p - center;
    const double c = std::cos(yawRadians), s = std::sin(yawRadians);
    return glm::dvec3((c * d.x + s * d.y) / halfSize.x, (-s * d.x + c * d.y) / halfSize.y,
                      d.z / halfSize.z);
}

bool ClipBox::contains(const glm::dvec3& p) const {
    const glm::dvec3 local = toBox(p);
    return std::abs(local.x) <= 1.0 && std::abs(local.y) <= 1.0 && std::abs(local.z) <= 1.0;
}

bool ClipBox::intersects(const glm::dvec3& min, double edge) const {
    // The cell's corners against the clip box's faces...
    std::array<glm::dvec3, 8> local;
    for (int i = 0; i < 8; ++i) {
        local[static_cast<std::size_t>(i)] =
            toBox(min + edge * glm::dvec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
    }
    for (int axis = 0; axis < 3; ++axis) {
        const auto [low, high] = std::minmax_element(
            local.begin(), local.end(),
            [axis](const glm::dvec3& a, const glm::dvec3& b) { return a[axis] < b[axis]; });
        if ((*low)[axis] > 1.0 || (*high)[axis] < -1.0) {
            return false;
        }
    }
    // ... and the clip box's corners against the cell's (axis-aligned) faces.
    const double c = std::cos(yawRadians), s = std::sin(yawRadians);
    const glm::dvec3 axisX(c * halfSize.x, s * halfSize.x, 0.0);
    const glm::dvec3 axisY(-s * halfSize.y, c * halfSize.y, 0.0);
    const glm::dvec3 axisZ(0.0, 0.0, halfSize.z);
    glm::dvec3 low(INFINITY), high(-INFINITY);
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 corner = center + ((i & 1) ? axisX : -axisX) +
                                  (((i >> 1) & 1) ? axisY : -axisY) +
                                  (((i >> 2) & 1) ? axisZ : -axisZ);
        low = glm::min(low, corner);
        high = glm::max(high, corner);
    }
    const glm::dvec3 max = min + glm::dvec3(edge);
    return !(low.x > max.x || low.y > max.y || low.z > max.z || high.x < min.x ||
             high.y < min.y || high.z < min.z);
}

glm::mat4 ClipBox::toBoxMatrix() const {
    glm::dmat4 m = glm::scale(glm::dmat4(1.0), 1.0 / halfSize);
    m = glm::rotate(m, -yawRadians, glm::dvec3(0.0, 0.0, 1.0));
    m = glm::translate(m, -center);
    return glm::mat4(m);
}

ClipBox toUnitCube(const ClipBox& box, const CubeTransform& cube) {
    return {(box.center - cube.origin) / cube.edge, box.halfSize / cube.edge, box.yawRadians};
}

} // namespace omicron
