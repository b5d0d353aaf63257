#include "scene/scene_generator.hpp"

#include "scene/scene_layout.hpp"
#include "scene/scene_random.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <vector>

namespace omicron {

namespace {

// Points per generator block: the unit of determinism, so it must never depend on threads.
constexpr std::uint64_t kBlockPoints = 4096;

// Shares of the points, as cumulative fractions: terrain, buildings, trees, then the statue.
constexpr double kTerrainShare = 0.50;
constexpr double kBuildingsShareEnd = 0.78;
constexpr double kTreesShareEnd = 0.92;

// Components interleave along the point index (a golden-ratio sequence), so any prefix of the
// cloud already shows the whole scene.
SceneComponent componentOf(std::uint64_t index) {
    const double u = static_cast<double>((index * 0x9E3779B97F4A7C15ull) >> 11) * 0x1.0p-53;
    if (u < kTerrainShare) {
        return SceneComponent::Terrain;
    }
    if (u < kBuildingsShareEnd) {
        return SceneComponent::Buildings;
    }
    return u < kTreesShareEnd ? SceneComponent::Trees : SceneComponent::Statue;
}

std::uint64_t blockSeed(std::uint64_t seed, std::uint64_t block) {
    std::uint64_t state = seed;
    const std::uint64_t mixedSeed = splitmix64(state);
    state = block ^ mixedSeed;
    return splitmix64(state);
}

const SceneLayout& sceneLayout() {
    static const SceneLayout layout;
    return layout;
}

} // namespace

GeneratedScene generateScene(std::uint64_t pointCount, std::uint64_t seed) {
    const SceneLayout& layout = sceneLayout();
    GeneratedScene scene;
    PointBatch& points = scene.points;
    points.attributes = AttributeSet(Attribute::Normal) | Attribute::Color;
    const auto count = static_cast<std::size_t>(pointCount);
    points.positions.resize(count); // metres at first, the unit cube once the bounds are known
    points.normals.resize(count);
    points.colors.resize(count);

    const std::uint64_t blocks = (pointCount + kBlockPoints - 1) / kBlockPoints;
    std::vector<Bounds> blockBounds(static_cast<std::size_t>(blocks));
    tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, blocks), [&](const auto& range) {
        for (std::uint64_t block = range.begin(); block != range.end(); ++block) {
            SceneRandom random(blockSeed(seed, block));
            Bounds bounds;
            const std::uint64_t end = std::min(pointCount, (block + 1) * kBlockPoints);
            for (std::uint64_t i = block * kBlockPoints; i < end; ++i) {
                const ScenePoint point = layout.sample(componentOf(i), random);
                const glm::vec3 position(point.position);
                points.positions[i] = position;
                points.normals[i] = glm::vec3(point.normal);
                points.colors[i] = point.color;
                bounds.extend(glm::dvec3(position));
            }
            blockBounds[block] = bounds;
        }
    });
    for (const Bounds& bounds : blockBounds) { // min/max: the order cannot change the result
        scene.sourceBounds.extend(bounds);
    }
    scene.cube = CubeTransform::fromBounds(scene.sourceBounds);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1 << 16), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            points.positions[i] = scene.cube.toUnit(glm::dvec3(points.positions[i]));
        }
    });
    return scene;
}

} // namespace omicron
