// The LAS fields of a point record beyond position, intensity and colour, as the point model's
// LAS column keeps them (points/las_fields.hpp): read from a record of any point format
// (0 to 10) and written into one, converting between the legacy layout of formats 0 to 5 and
// the LAS 1.4 layout of formats 6 to 10.
#pragma once

#include "points/las_fields.hpp"

#include <cstddef>
#include <cstdint>

namespace omicron::las {

// Formats 1, 3, 4, 5 and 6 to 10 carry a GPS time; 8 and 10 a near-infrared channel.
bool formatHasGpsTime(std::uint8_t pointFormat);
bool formatHasNir(std::uint8_t pointFormat);
// Formats 4, 5, 9 and 10 point into waveform packets, which omicron does not read.
bool formatHasWaveform(std::uint8_t pointFormat);

// The attributes a record of `pointFormat` with `recordLength` bytes gives the point model:
// intensity, the LAS column (with GPS time, NIR and extra bytes as the format has them) and
// colour where the format has it.
AttributeSet attributesOfFormat(std::uint8_t pointFormat, std::uint16_t recordLength);

// The fields of `record` (a record of `pointFormat`), through readLasColumn.
LasFields readLasFields(const std::uint8_t* record, std::uint8_t pointFormat);
// Fills one point's LAS column (`layout` of the cloud's attributes) from `record` (of
// `pointFormat`, `layout.extraBytes` extra bytes after its standard fields): the reader's hot
// path, equal to encodeLasFields(readLasFields(record)) plus the extra bytes.
void readLasColumn(const std::uint8_t* record, std::uint8_t pointFormat,
                   const LasColumnLayout& layout, std::uint8_t* column);
// readLasColumn for `count` records `stride` bytes apart, into consecutive columns of
// `layout.bytes`: the format's branches are taken once per block, not per point.
void readLasColumns(const std::uint8_t* records, std::size_t count, std::size_t stride,
                    std::uint8_t pointFormat, const LasColumnLayout& layout, std::uint8_t* columns);

// Writes `fields` into `record` (of `pointFormat`, zeroed before): classification, returns,
// flags, user data, scan angle, point source ID, and GPS time and NIR where the format has
// them. A legacy format keeps classes 0 to 31 and scan angles rounded to whole degrees.
void writeLasFields(const LasFields& fields, std::uint8_t pointFormat, std::uint8_t* record);

} // namespace omicron::las
