// The project's default cloud: a procedural, scan-like scene (terrain, buildings, trees and a
// statue around a terrestrial scanner; see scene_layout.hpp), so the programs and benchmarks
// have a large realistic input without a download.
#pragma once

#include "points/bounds.hpp"
#include "points/cube_transform.hpp"
#include "points/point_batch.hpp"

#include <cstdint>

namespace omicron {

struct GeneratedScene {
    PointBatch points;   // positions in the unit cube of `cube`; unit normals; colours
    CubeTransform cube;  // unit cube -> metres
    Bounds sourceBounds; // metres
};

// Exactly `pointCount` points. Deterministic: the same (pointCount, seed) gives bit-identical
// points whatever the number of threads, because every block of points draws from its own
// generator seeded by (seed, block index). Parallel (oneTBB) over blocks.
GeneratedScene generateScene(std::uint64_t pointCount, std::uint64_t seed);

} // namespace omicron
