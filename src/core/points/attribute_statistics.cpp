#include "points/attribute_statistics.hpp"

namespace omicron {

void AttributeStatistics::add(const PointBatch& batch) {
    m_attributes = batch.attributes;
    m_points += batch.size();
    for (const std::uint16_t intensity : batch.intensities) {
        m_intensity.add(intensity);
    }
    for (const glm::u8vec3 color : batch.colors) {
        m_red.add(color.r);
        m_green.add(color.g);
        m_blue.add(color.b);
    }
    const std::size_t lasBytes = batch.attributes.lasBytes();
    for (std::size_t i = 0; lasBytes != 0 && i < batch.size(); ++i) {
        const LasFields f = decodeLasFields(batch.attributes, batch.las.data() + i * lasBytes);
        ++m_classes[f.classification];
        m_returnNumber.add(f.returnNumber());
        m_numberOfReturns.add(f.numberOfReturns());
        m_scanAngle.add(f.scanAngleDegrees());
        m_userData.add(f.userData);
        m_pointSourceId.add(f.pointSourceId);
        m_scannerChannel.add((f.flags >> las_flag::kScannerChannelShift) & 3);
        for (int flag = 0; flag < 4; ++flag) {
            m_flagCounts[flag] += (f.flags >> flag) & 1u;
        }
        if (batch.attributes.has(Attribute::GpsTime)) {
            m_gpsTime.add(f.gpsTime);
        }
        if (batch.attributes.has(Attribute::Nir)) {
            m_nir.add(f.nir);
        }
    }
}

std::vector<NamedRange> AttributeStatistics::ranges() const {
    std::vector<NamedRange> out;
    const auto put = [&](const char* name, const ValueRange& range) {
        if (!range.empty) {
            out.push_back({name, range});
        }
    };
    put("intensity", m_intensity);
    put("red", m_red);
    put("green", m_green);
    put("blue", m_blue);
    if (m_attributes.has(Attribute::Las) && m_points != 0) {
        ValueRange classes;
        for (int c = 0; c < kLasClassCount; ++c) {
            if (m_classes[static_cast<std::size_t>(c)] != 0) {
                classes.add(c);
            }
        }
        put("classification", classes);
        put("return number", m_returnNumber);
        put("number of returns", m_numberOfReturns);
        put("scan angle (degrees)", m_scanAngle);
        put("user data", m_userData);
        put("point source id", m_pointSourceId);
        put("scanner channel", m_scannerChannel);
        const char* flags[4] = {"synthetic flag", "key-point flag", "withheld flag",
                                "overlap flag"};
        for (int flag = 0; flag < 4; ++flag) {
            ValueRange values; // 0 when some point lacks the flag, 1 when some has it
            if (m_flagCounts[flag] < m_points) {
                values.add(0);
            }
            if (m_flagCounts[flag] > 0) {
                values.add(1);
            }
            put(flags[flag], values);
        }
    }
    put("gps time", m_gpsTime);
    put("nir", m_nir);
    return out;
}

std::vector<std::string> attributeNames(AttributeSet attributes) {
    std::vector<std::string> names;
    const auto when = [&](bool present, const char* name) {
        if (present) {
            names.emplace_back(name);
        }
    };
    when(attributes.has(Attribute::Normal), "normal");
    when(attributes.has(Attribute::Color), "color");
    when(attributes.has(Attribute::Intensity), "intensity");
    const bool las = attributes.has(Attribute::Las);
    for (const char* name : {"classification", "classification flags", "return number",
                             "number of returns", "scan angle", "user data", "point source id",
                             "scanner channel", "scan direction", "edge of flight line"}) {
        when(las, name);
    }
    when(attributes.has(Attribute::GpsTime), "gps time");
    when(attributes.has(Attribute::Nir), "nir");
    if (attributes.extraBytes() != 0) {
        names.push_back("extra bytes (" + std::to_string(attributes.extraBytes()) + ")");
    }
    return names;
}

} // namespace omicron
