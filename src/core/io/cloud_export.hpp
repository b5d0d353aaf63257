// Writing a kept SortedCloud back out as an ordinary cloud file (the desktop application's
// File -> Export Points): PLY or LAS chosen by the file name, points in Morton order.
#pragma once

#include "io/las/las_writer.hpp"
#include "points/clip_box.hpp"
#include "points/sorted_cloud.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace omicron {

// Writes points [0, cloud.sortedEnd()) to `path`: binary PLY for ".ply", LAS for ".las" (any
// case; see lasExportOptions); coordinates in source units. With
// `clip` (source units), only the points inside it. Returns the points written. Throws
// OutputError naming the file for another extension, an empty cloud (or clip) or an I/O
// failure.
std::uint64_t exportCloudPoints(const std::string& path, const SortedCloud& cloud,
                                const std::optional<ClipBox>& clip = std::nullopt);

// How a cloud is written as LAS: a cloud read from LAS or LAZ (Attribute::Las) as LAS 1.4
// point format 6, 7 (colour) or 8 (colour and NIR) with every LAS field and its extra bytes
// (described by an Extra Bytes record: the source's `extraBytesDescriptors` when they describe
// them, else as undocumented bytes); any other as LAS 1.2 format 2 or 0 (with or without
// colour). Integers relative to the cube's corner at a power-of-ten step.
// The source's coordinate system records (`projectionRecords`, as CloudInfo has them) go
// first, so the file keeps its georeference.
LasWriteOptions lasExportOptions(AttributeSet attributes, const CubeTransform& cube,
                                 const std::vector<std::uint8_t>& extraBytesDescriptors = {},
                                 const std::vector<std::uint8_t>& projectionRecords = {});

} // namespace omicron
