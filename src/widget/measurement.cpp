#include "measurement.hpp"

#include <cmath>
#include <glm/geometric.hpp>

namespace omicron {

double Measurement::value() const {
    if (points.size() < 2) {
        return 0.0;
    }
    switch (kind) {
    case MeasureKind::Distance:
        return glm::length(points[1] - points[0]);
    case MeasureKind::Height:
        return points[1].z - points[0].z;
    case MeasureKind::Polyline: {
        double length = 0.0;
        for (std::size_t i = 1; i < points.size(); ++i) {
            length += glm::length(points[i] - points[i - 1]);
        }
        return length;
    }
    case MeasureKind::Area: {
        // Relative to the first point: georeferenced coordinates (10^6) would lose the
        // products' low digits otherwise.
        double twice = 0.0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const glm::dvec3 a = points[i] - points[0];
            const glm::dvec3 b = points[(i + 1) % points.size()] - points[0];
            twice += a.x * b.y - b.x * a.y;
        }
        return std::abs(twice) / 2.0;
    }
    }
    return 0.0;
}

QString Measurement::valueText() const {
    const QString number = QString::number(value(), 'f', 3);
    switch (kind) {
    case MeasureKind::Height:
        return number + QStringLiteral(" (height)");
    case MeasureKind::Polyline:
        return number + QStringLiteral(" (length)");
    case MeasureKind::Area:
        return number + QStringLiteral(" (area, units\u00B2)");
    case MeasureKind::Distance:
        break;
    }
    return number;
}

std::size_t Measurement::fixedPoints(MeasureKind kind) {
    return kind == MeasureKind::Distance || kind == MeasureKind::Height ? 2 : 0;
}

std::size_t Measurement::minimumPoints(MeasureKind kind) {
    return kind == MeasureKind::Area ? 3 : 2;
}

QString Measurement::kindName(MeasureKind kind) {
    switch (kind) {
    case MeasureKind::Distance:
        return QStringLiteral("distance");
    case MeasureKind::Height:
        return QStringLiteral("height");
    case MeasureKind::Polyline:
        return QStringLiteral("polyline");
    case MeasureKind::Area:
        return QStringLiteral("area");
    }
    return {};
}

} // namespace omicron
