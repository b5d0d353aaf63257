// Writing a kept SortedCloud back out as an ordinary cloud file (the desktop application's
// File -> Export Points): PLY or LAS chosen by the file name, points in Morton order.
#pragma once

#include "points/clip_box.hpp"
#include "points/sorted_cloud.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace omicron {

// Writes points [0, cloud.sortedEnd()) to `path`: binary PLY for ".ply", LAS 1.2 point format
// 2 or 0 (with or without colour) for ".las" (any case); coordinates in source units. With
// `clip` (source units), only the points inside it. Returns the points written. Throws
// OutputError naming the file for another extension, an empty cloud (or clip) or an I/O
// failure.
std::uint64_t exportCloudPoints(const std::string& path, const SortedCloud& cloud,
                                const std::optional<ClipBox>& clip = std::nullopt);

} // namespace omicron
