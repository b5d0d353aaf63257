// The point record of a Potree 2.0 export ("DEFAULT" encoding: one little-endian record per
// point in octree.bin) and its declaration in metadata.json, as PotreeConverter 2 writes them:
//   position   int32 x 3   stored = floor(unit x 2^30), value = stored x scale + offset
//   intensity  uint16      when the cloud has it
//   LAS fields             when the cloud was read from LAS or LAZ: return number, number of
//                          returns, classification (uint8), scan angle (int16, 0.006 degree
//                          steps), user data (uint8), point source id (uint16), gps-time
//                          (double, where the source had it)
//   rgb        uint16 x 3  when the cloud has it: the 8-bit colour x 257 (Potree's loaders take
//                          values above 255 as 16-bit, so 255 reads back as 255)
// in PotreeConverter's order for LAS input (position, intensity, ..., rgb). Each declaration
// carries the name, size, numElements, elementSize, type, and the min, max, scale and offset
// PotreeConverter 2.1 adds. Normals and splat attributes are not written: PotreeConverter's
// output has no field for them.
#pragma once

#include "points/sorted_cloud.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace omicron {

// Quantisation steps per cube edge of the exported int32 positions (PotreeConverter's bound:
// 30 bits, so that loaders reading them as unsigned agree).
inline constexpr std::uint32_t kPotreeStepsPerEdge = 1u << 30;

class PotreeRecordEncoder {
public:
    explicit PotreeRecordEncoder(const SortedCloud& cloud);

    std::size_t recordBytes() const { return m_recordBytes; }
    bool hasColor() const { return m_color; }
    bool hasIntensity() const { return m_intensity; }
    bool hasLasFields() const { return m_las; }

    // Writes point `index` of the cloud into `record` (recordBytes() bytes) and widens each
    // attribute's range by it.
    void encode(std::uint32_t index, std::uint8_t* record);

    // The "attributes" array of metadata.json (`indent` before each line), positions in
    // source units from `scale` and `offset`. Ranges are those of the encoded points.
    std::string attributesJson(double scale, const std::array<double, 3>& offset,
                               const std::string& indent) const;

private:
    const SortedCloud& m_cloud;
    bool m_color, m_intensity, m_las, m_gpsTime;
    std::size_t m_recordBytes;
    // Ranges of the LAS fields, in record order (kLasFields in the .cpp).
    std::array<double, 7> m_lasMin, m_lasMax;
    std::array<std::int32_t, 3> m_positionMin, m_positionMax;
    std::array<std::uint16_t, 3> m_rgbMin, m_rgbMax;
    std::uint16_t m_intensityMin, m_intensityMax;
};

// floor(unit x 2^30) clamped to the cube: a point on the cube's far face stays in the last
// step, so it lies inside its node's box.
std::int32_t potreeQuantize(float unit);

} // namespace omicron
