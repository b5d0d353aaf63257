// The viewer's camera, in the hierarchy's unit cube (z up, as scans are): an orbit camera
// around a pivot that can switch to fly mode, with the moves scan operators know from
// CloudCompare and Potree. Pure math (GLM): no GL, no Qt, tested alone.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace omicron {

enum class StandardView;

class ViewCamera {
public:
    static constexpr double kDefaultFovYDegrees = 50.0;

    // Eye, looked-at pivot and orientation.
    glm::dvec3 pivot() const { return m_pivot; }
    glm::dvec3 eye() const;
    double distance() const { return m_distance; }
    double yawRadians() const { return m_yaw; }
    double pitchRadians() const { return m_pitch; }
    double fovYRadians() const { return m_fovY; }
    glm::dvec3 forward() const; // unit vector from the eye towards the pivot
    glm::dvec3 right() const;
    glm::dvec3 up() const;

    glm::dmat4 viewMatrix() const;
    // Near and far planes follow the scene box so depth precision stays usable at any zoom.
    glm::dmat4 projectionMatrix(double aspect) const;
    // Pixels covered by a unit length at unit distance, for a viewport `heightPx` high.
    double pixelsPerUnitAtUnitDistance(double heightPx) const;
    // What a point's or a cell's size on screen is scaled by: pixels per unit at unit distance
    // (then divided by the distance), or in an orthographic view pixels per unit anywhere
    // (the view is as high as the perspective one's at the pivot).
    double screenScale(double heightPx) const;

    // Orthographic projection (parallel lines stay parallel: sections, facades, plans).
    // Switching keeps the pivot's framing.
    void setOrthographic(bool on) { m_orthographic = on; }
    bool orthographic() const { return m_orthographic; }

    // The box the camera frames and clips against (the cloud's cube).
    void setSceneBox(const glm::dvec3& min, const glm::dvec3& max);

    // Frames the scene box from the current direction.
    void fit();
    void setStandardView(StandardView view);

    // Mouse moves, in pixels of a viewport `heightPx` high.
    void orbit(double dxPx, double dyPx);
    void pan(double dxPx, double dyPx, double heightPx);
    // Moves eye and pivot towards `target` by `factor` (< 1 zooms in), keeping the direction:
    // zoom to cursor when `target` is the point under the cursor.
    void zoomToward(const glm::dvec3& target, double factor);
    // Keeps the eye, turns to look at `pivot` (double-click sets the pivot on a picked point).
    void setPivot(const glm::dvec3& pivot);
    void setPose(const glm::dvec3& pivot, double distance, double yawRadians, double pitchRadians);

    // Fly mode: turns the view around the eye, and moves eye and pivot together.
    void look(double dxPx, double dyPx);
    void fly(const glm::dvec3& localDirection, double seconds);
    // Fly speed in units per second: a tenth of the scene box per second by default.
    double flySpeed() const;

private:
    glm::dvec3 m_pivot{0.5, 0.5, 0.5};
    double m_distance = 2.0;
    double m_yaw = -2.3561944901923448;  // from the (-x, -y) side
    double m_pitch = 0.6;                // above the horizon
    double m_fovY = kDefaultFovYDegrees * 3.14159265358979323846 / 180.0;
    glm::dvec3 m_boxMin{0.0};
    glm::dvec3 m_boxMax{1.0};
    bool m_orthographic = false;
};

} // namespace omicron
