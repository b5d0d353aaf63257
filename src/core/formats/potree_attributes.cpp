#include "formats/potree_attributes.hpp"

#include "io/raw_bytes.hpp"
#include "points/las_fields.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

namespace omicron {

namespace {

std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.17g", value);
    return text;
}

std::string list(const std::vector<double>& values) {
    std::string text("[");
    for (std::size_t i = 0; i < values.size(); ++i) {
        text.append(i == 0 ? "" : ", ").append(number(values[i]));
    }
    return text.append("]");
}

struct Declaration {
    const char* name;
    int numElements;
    int elementSize;
    const char* type;
    std::vector<double> min, max;
};

// Appended piece by piece: GCC 12's -Wrestrict misfires on "literal" + std::string.
std::string declarationJson(const Declaration& d, const std::string& indent) {
    const auto n = static_cast<std::size_t>(d.numElements);
    std::string json(indent);
    json.append("{\"name\": \"").append(d.name).append("\", \"description\": \"\", ");
    json.append("\"size\": ").append(std::to_string(d.numElements * d.elementSize));
    json.append(", \"numElements\": ").append(std::to_string(d.numElements));
    json.append(", \"elementSize\": ").append(std::to_string(d.elementSize));
    json.append(", \"type\": \"").append(d.type).append("\"");
    json.append(", \"min\": ").append(list(d.min)).append(", \"max\": ").append(list(d.max));
    json.append(", \"scale\": ").append(list(std::vector<double>(n, 1.0)));
    json.append(", \"offset\": ").append(list(std::vector<double>(n, 0.0))).append("}");
    return json;
}

// The LAS fields of a record, in PotreeConverter's order for LAS input.
struct LasFieldSpec {
    const char* name;
    int size;
    const char* type;
};
constexpr std::array<LasFieldSpec, 7> kLasFields{{{"return number", 1, "uint8"},
                                                  {"number of returns", 1, "uint8"},
                                                  {"classification", 1, "uint8"},
                                                  {"scan angle", 2, "int16"},
                                                  {"user data", 1, "uint8"},
                                                  {"point source id", 2, "uint16"},
                                                  {"gps-time", 8, "double"}}};

std::array<double, 7> lasFieldValues(const LasFields& f) {
    return {double(f.returnNumber()),
            double(f.numberOfReturns()),
            double(f.classification),
            double(f.scanAngle),
            double(f.userData),
            double(f.pointSourceId),
            f.gpsTime};
}

} // namespace

std::int32_t potreeQuantize(float unit) {
    const double steps = std::floor(static_cast<double>(unit) * kPotreeStepsPerEdge);
    return static_cast<std::int32_t>(std::clamp(steps, 0.0, double(kPotreeStepsPerEdge - 1)));
}

PotreeRecordEncoder::PotreeRecordEncoder(const SortedCloud& cloud)
    : m_cloud(cloud), m_color(cloud.attributes().has(Attribute::Color)),
      m_intensity(cloud.attributes().has(Attribute::Intensity)),
      m_las(cloud.attributes().has(Attribute::Las)),
      m_gpsTime(cloud.attributes().has(Attribute::GpsTime)),
      m_recordBytes(12 + (m_intensity ? 2 : 0) + (m_las ? 8 : 0) + (m_gpsTime ? 8 : 0) +
                    (m_color ? 6 : 0)) {
    m_lasMin.fill(std::numeric_limits<double>::max());
    m_lasMax.fill(std::numeric_limits<double>::lowest());
    m_positionMin.fill(std::numeric_limits<std::int32_t>::max());
    m_positionMax.fill(std::numeric_limits<std::int32_t>::min());
    m_rgbMin.fill(65535);
    m_rgbMax.fill(0);
    m_intensityMin = 65535;
    m_intensityMax = 0;
}

void PotreeRecordEncoder::encode(std::uint32_t index, std::uint8_t* record) {
    const glm::vec3 unit = m_cloud.position(index);
    for (int axis = 0; axis < 3; ++axis) {
        const std::int32_t stored = potreeQuantize(unit[axis]);
        storeRaw(record + 4 * axis, stored);
        m_positionMin[axis] = std::min(m_positionMin[axis], stored);
        m_positionMax[axis] = std::max(m_positionMax[axis], stored);
    }
    std::size_t at = 12;
    if (m_intensity) {
        const std::uint16_t value = m_cloud.intensities()[index];
        storeRaw(record + at, value);
        m_intensityMin = std::min(m_intensityMin, value);
        m_intensityMax = std::max(m_intensityMax, value);
        at += 2;
    }
    if (m_las) {
        const LasFields fields = decodeLasFields(m_cloud.attributes(), m_cloud.lasRecord(index));
        record[at] = static_cast<std::uint8_t>(fields.returnNumber());
        record[at + 1] = static_cast<std::uint8_t>(fields.numberOfReturns());
        record[at + 2] = fields.classification;
        storeRaw(record + at + 3, fields.scanAngle);
        record[at + 5] = fields.userData;
        storeRaw(record + at + 6, fields.pointSourceId);
        at += 8;
        if (m_gpsTime) {
            storeRaw(record + at, fields.gpsTime);
            at += 8;
        }
        const std::array<double, 7> values = lasFieldValues(fields);
        for (std::size_t f = 0; f < values.size(); ++f) {
            m_lasMin[f] = std::min(m_lasMin[f], values[f]);
            m_lasMax[f] = std::max(m_lasMax[f], values[f]);
        }
    }
    if (m_color) {
        const glm::u8vec3 color = m_cloud.color(index);
        for (int c = 0; c < 3; ++c) {
            const auto value = static_cast<std::uint16_t>(color[c] * 257u);
            storeRaw(record + at + 2 * c, value);
            m_rgbMin[c] = std::min(m_rgbMin[c], value);
            m_rgbMax[c] = std::max(m_rgbMax[c], value);
        }
    }
}

std::string PotreeRecordEncoder::attributesJson(double scale, const std::array<double, 3>& offset,
                                                const std::string& indent) const {
    // An export without points (never: a complete hierarchy holds at least one) would show
    // the empty ranges' sentinels; clamp them to something a loader can parse.
    const bool any = m_positionMin[0] <= m_positionMax[0];
    Declaration position{"position", 3, 4, "int32", {}, {}};
    for (int axis = 0; axis < 3; ++axis) {
        position.min.push_back(any ? m_positionMin[axis] * scale + offset[axis] : offset[axis]);
        position.max.push_back(any ? m_positionMax[axis] * scale + offset[axis] : offset[axis]);
    }
    std::string json("[\n");
    json.append(declarationJson(position, indent));
    if (m_intensity) {
        json.append(",\n").append(declarationJson({"intensity",
                                                   1,
                                                   2,
                                                   "uint16",
                                                   {double(any ? m_intensityMin : 0)},
                                                   {double(any ? m_intensityMax : 0)}},
                                                  indent));
    }
    if (m_las) {
        for (std::size_t f = 0; f < kLasFields.size(); ++f) {
            if (f + 1 == kLasFields.size() && !m_gpsTime) {
                break;
            }
            const LasFieldSpec& spec = kLasFields[f];
            json.append(",\n").append(declarationJson({spec.name,
                                                       1,
                                                       spec.size,
                                                       spec.type,
                                                       {any ? m_lasMin[f] : 0.0},
                                                       {any ? m_lasMax[f] : 0.0}},
                                                      indent));
        }
    }
    if (m_color) {
        Declaration rgb{"rgb", 3, 2, "uint16", {}, {}};
        for (int c = 0; c < 3; ++c) {
            rgb.min.push_back(any ? m_rgbMin[c] : 0);
            rgb.max.push_back(any ? m_rgbMax[c] : 0);
        }
        json.append(",\n").append(declarationJson(rgb, indent));
    }
    // The closing bracket one level out, as the array's opening line sits.
    json.append("\n").append(indent.substr(0, indent.size() >= 2 ? indent.size() - 2 : 0));
    return json.append("]");
}

} // namespace omicron
