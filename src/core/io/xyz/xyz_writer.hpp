// Writes a point batch as XYZ text, atomically: one point per line, "x y z [r g b] [nx ny nz]",
// or "x y z intensity [r g b]" when the batch has intensities and no normals (the reader has
// no layout with both). The result reads back with openXyzReader.
#pragma once

#include "io/atomic_file_writer.hpp"
#include "points/cube_transform.hpp"
#include "points/point_batch.hpp"

#include <string>

namespace omicron {

// Positions are mapped back to source units with `cube`, minus `offset`, and written with as
// many decimals as the cube's float resolution needs (edge / 2^24); normals get six decimals,
// always with a decimal point, so a six-column file is never mistaken for colours. A first
// comment line names the columns. Throws OutputError; the target is untouched on failure.
void writeXyz(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const glm::dvec3& offset = glm::dvec3(0.0));

} // namespace omicron
