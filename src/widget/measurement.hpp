// Measurements a scan operator takes in the view (CloudView's measure tool): point-to-point
// distance, height difference, polyline length and the horizontal area of a polygon, between
// points picked on the cloud, in the file's coordinates and units.
#pragma once

#include <QString>
#include <glm/vec3.hpp>
#include <vector>

namespace omicron {

enum class MeasureKind { Distance, Height, Polyline, Area };

struct Measurement {
    MeasureKind kind = MeasureKind::Distance;
    std::vector<glm::dvec3> points; // picked points, source coordinates

    // Distance: between the two points; Height: the second's z minus the first's; Polyline:
    // the sum of its segments; Area: of the polygon's projection on the xy plane (shoelace).
    double value() const;
    // "13.000", "-2.500 (height)", "100.000 (area, units²)": for labels and the dock.
    QString valueText() const;
    // Whether it has all its points: two for a distance or height; a polyline (two or more)
    // or an area (three or more) is complete once finished by the user.
    bool complete() const { return m_finished || fixedPoints(kind) == points.size(); }
    void finish() { m_finished = true; }
    bool canFinish() const { return points.size() >= minimumPoints(kind); }

    static std::size_t fixedPoints(MeasureKind kind); // 0: open-ended
    static std::size_t minimumPoints(MeasureKind kind);
    static QString kindName(MeasureKind kind);

private:
    bool m_finished = false;
};

} // namespace omicron
