// The ASPRS standard point classes of LAS 1.4 (R15, table 17): names, and the colours the
// viewer's classification mode draws them in. The LAS specification gives no colours; these
// follow the convention of lidar viewers (ground brown, vegetation in greens by height,
// buildings orange, water blue, noise magenta) so a scan operator reads them at a glance.
#pragma once

#include <cstdint>
#include <glm/gtc/type_precision.hpp>
#include <string>

namespace omicron {

inline constexpr int kLasClassCount = 256;

// "Ground", "High Vegetation", ...; "Reserved 23" for 23-63, "User 64" for 64-255.
std::string lasClassName(int classification);

// The colour of a class in the classification colour mode (8-bit sRGB).
glm::u8vec3 lasClassColor(int classification);

} // namespace omicron
