// The ranges of a cloud's attributes, gathered batch by batch: what `omicron-cli info` lists
// and what a viewer needs for its colour modes (the GPS time span, the classes present).
#pragma once

#include "points/asprs_classes.hpp"
#include "points/las_fields.hpp"
#include "points/point_batch.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace omicron {

// A closed range of one numeric field; empty until a value is added.
struct ValueRange {
    double min = 0.0;
    double max = 0.0;
    bool empty = true;

    void add(double value) {
        if (empty) {
            min = max = value;
            empty = false;
        } else {
            min = value < min ? value : min;
            max = value > max ? value : max;
        }
    }
    void add(const ValueRange& other) {
        if (!other.empty) {
            add(other.min);
            add(other.max);
        }
    }
};

// One named range, as listed: "intensity", "classification", "gps time", ...
struct NamedRange {
    std::string name;
    ValueRange range;
};

class AttributeStatistics {
public:
    // Adds every point of `batch`.
    void add(const PointBatch& batch);

    AttributeSet attributes() const { return m_attributes; }
    std::uint64_t points() const { return m_points; }
    // Points per classification value (all zero without the LAS column).
    const std::array<std::uint64_t, kLasClassCount>& classCounts() const { return m_classes; }
    // The ranges of the attributes present, in a fixed order (colour as red, green, blue).
    std::vector<NamedRange> ranges() const;

private:
    AttributeSet m_attributes;
    std::uint64_t m_points = 0;
    std::array<std::uint64_t, kLasClassCount> m_classes{};
    ValueRange m_intensity, m_red, m_green, m_blue;
    ValueRange m_returnNumber, m_numberOfReturns, m_scanAngle, m_userData, m_pointSourceId,
        m_gpsTime, m_nir, m_scannerChannel;
    std::uint64_t m_flagCounts[4] = {}; // synthetic, key-point, withheld, overlap
};

// "color", "intensity", "classification", ... : the attributes' names as info lists them.
std::vector<std::string> attributeNames(AttributeSet attributes);

} // namespace omicron
