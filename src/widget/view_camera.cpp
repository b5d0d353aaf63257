#include "view_camera.hpp"

#include "render_settings.hpp"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/geometric.hpp>

namespace omicron {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxPitch = kPi / 2.0 - 1e-3; // never straight up or down: up vector stays valid
constexpr double kOrbitRadiansPerPixel = 0.006;
constexpr double kLookRadiansPerPixel = 0.003;

glm::dvec3 directionFromAngles(double yaw, double pitch) {
    // The direction from the pivot to the eye.
    return {std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch)};
}

} // namespace

glm::dvec3 ViewCamera::eye() const { return m_pivot + m_distance * directionFromAngles(m_yaw, m_pitch); }

glm::dvec3 ViewCamera::forward() const { return -directionFromAngles(m_yaw, m_pitch); }

glm::dvec3 ViewCamera::right() const {
    return glm::normalize(glm::cross(forward(), glm::dvec3(0.0, 0.0, 1.0)));
}

glm::dvec3 ViewCamera::up() const { return glm::cross(right(), forward()); }

glm::dmat4 ViewCamera::viewMatrix() const { return glm::lookAt(eye(), m_pivot, up()); }

glm::dmat4 ViewCamera::projectionMatrix(double aspect) const {
    const glm::dvec3 center = (m_boxMin + m_boxMax) * 0.5;
    const double radius = glm::length(m_boxMax - m_boxMin) * 0.5;
    const double centerDistance = glm::dot(center - eye(), forward());
    const double farPlane = std::max(centerDistance + radius * 1.5, 1e-3);
    // Near: close enough to fly inside the cloud, far enough for 24-bit depth (ratio <= 1e5).
    if (m_orthographic) {
        // As high as the perspective view at the pivot; depth is linear, so the near plane
        // may sit behind the eye and keep the whole box.
        const double halfHeight = m_distance * std::tan(m_fovY * 0.5);
        const double halfWidth = halfHeight * std::max(aspect, 1e-3);
        return glm::ortho(-halfWidth, halfWidth, -halfHeight, halfHeight,
                          centerDistance - radius * 1.5, farPlane);
    }
    const double nearPlane = std::max({centerDistance - radius * 1.5, farPlane * 1e-5, 1e-6});
    return glm::perspective(m_fovY, std::max(aspect, 1e-3), nearPlane, farPlane);
}

double ViewCamera::screenScale(double heightPx) const {
    const double perspective = pixelsPerUnitAtUnitDistance(heightPx);
    return m_orthographic ? perspective / std::max(m_distance, 1e-9) : perspective;
}

double ViewCamera::pixelsPerUnitAtUnitDistance(double heightPx) const {
    return heightPx / (2.0 * std::tan(m_fovY * 0.5));
}

void ViewCamera::setSceneBox(const glm::dvec3& min, const glm::dvec3& max) {
    m_boxMin = min;
    m_boxMax = max;
}

void ViewCamera::fit() {
    const double radius = std::max(glm::length(m_boxMax - m_boxMin) * 0.5, 1e-9);
    m_pivot = (m_boxMin + m_boxMax) * 0.5;
    m_distance = radius / std::sin(m_fovY * 0.5) * 1.05;
}

void ViewCamera::setStandardView(StandardView view) {
    switch (view) {
    case StandardView::Top:
        m_yaw = -kPi / 2.0;
        m_pitch = kMaxPitch;
        break;
    case StandardView::Bottom:
        m_yaw = -kPi / 2.0;
        m_pitch = -kMaxPitch;
        break;
    case StandardView::Front:
        m_yaw = -kPi / 2.0;
        m_pitch = 0.0;
        break;
    case StandardView::Back:
        m_yaw = kPi / 2.0;
        m_pitch = 0.0;
        break;
    case StandardView::Left:
        m_yaw = kPi;
        m_pitch = 0.0;
        break;
    case StandardView::Right:
        m_yaw = 0.0;
        m_pitch = 0.0;
        break;
    case StandardView::Iso:
        m_yaw = -3.0 * kPi / 4.0;
        m_pitch = 0.6;
        break;
    }
    fit();
}

void ViewCamera::orbit(double dxPx, double dyPx) {
    m_yaw -= dxPx * kOrbitRadiansPerPixel;
    m_pitch = std::clamp(m_pitch + dyPx * kOrbitRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void ViewCamera::pan(double dxPx, double dyPx, double heightPx) {
    const double unitsPerPixel = m_distance / pixelsPerUnitAtUnitDistance(std::max(heightPx, 1.0));
    m_pivot += (-dxPx * right() + dyPx * up()) * unitsPerPixel;
}

void ViewCamera::zoomToward(const glm::dvec3& target, double factor) {
    const glm::dvec3 newEye = target + (eye() - target) * factor;
    m_pivot = target + (m_pivot - target) * factor;
    m_distance = std::max(glm::length(newEye - m_pivot), 1e-7);
}

void ViewCamera::setPivot(const glm::dvec3& pivot) {
    const glm::dvec3 keptEye = eye();
    const glm::dvec3 toEye = keptEye - pivot;
    const double length = glm::length(toEye);
    if (length < 1e-9) {
        return;
    }
    m_pivot = pivot;
    m_distance = length;
    m_pitch = std::clamp(std::asin(std::clamp(toEye.z / length, -1.0, 1.0)), -kMaxPitch, kMaxPitch);
    m_yaw = std::atan2(toEye.y, toEye.x);
}

void ViewCamera::setPose(const glm::dvec3& pivot, double distance, double yawRadians,
                         double pitchRadians) {
    m_pivot = pivot;
    m_distance = std::max(distance, 1e-7);
    m_yaw = yawRadians;
    m_pitch = std::clamp(pitchRadians, -kMaxPitch, kMaxPitch);
}

void ViewCamera::look(double dxPx, double dyPx) {
    const glm::dvec3 keptEye = eye();
    m_yaw -= dxPx * kLookRadiansPerPixel;
    m_pitch = std::clamp(m_pitch + dyPx * kLookRadiansPerPixel, -kMaxPitch, kMaxPitch);
    m_pivot = keptEye - m_distance * directionFromAngles(m_yaw, m_pitch);
}

void ViewCamera::fly(const glm::dvec3& localDirection, double seconds) {
    const glm::dvec3 move = (localDirection.x * right() + localDirection.y * up() +
                             localDirection.z * forward()) *
                            (flySpeed() * seconds);
    m_pivot += move;
}

double ViewCamera::flySpeed() const { return glm::length(m_boxMax - m_boxMin) * 0.1; }

} // namespace omicron
