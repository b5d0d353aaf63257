#include "front/front_pick.hpp"

#include <algorithm>
#include <cmath>

namespace omicron {

namespace {

// Distance from `p` to the node's cell (0 inside).
double distanceToCell(morton::Code code, const glm::dvec3& p) {
    const int level = morton::level(code);
    const morton::Cell cell = morton::decode(code);
    const double size = std::ldexp(1.0, -level);
    const glm::dvec3 low = glm::dvec3(cell.x, cell.y, cell.z) * size;
    const glm::dvec3 high = low + glm::dvec3(size);
    const glm::dvec3 outside = glm::max(glm::max(low - p, p - high), glm::dvec3(0.0));
    return std::sqrt(outside.x * outside.x + outside.y * outside.y + outside.z * outside.z);
}

} // namespace

std::optional<DrawnPoint> nearestDrawnPoint(const Hierarchy& hierarchy,
                                            std::span<const FrontEntry> entries,
                                            const glm::dvec3& unitPosition, double maxDistance) {
    const SortedCloud& cloud = hierarchy.cloud();
    std::optional<DrawnPoint> best;
    double bestSquared = maxDistance * maxDistance;
    for (const FrontEntry& entry : entries) {
        if (entry.placeholder || !entry.visible ||
            distanceToCell(entry.code, unitPosition) > std::sqrt(bestSquared)) {
            continue;
        }
        const OctreeNode& node = hierarchy.node(entry.level(), entry.index);
        for (std::uint32_t i = 0; i < node.pointCount; ++i) {
            const std::uint32_t index = node.heldPoint(i);
            const glm::vec3 position = cloud.position(index);
            const glm::dvec3 offset = glm::dvec3(position) - unitPosition;
            const double squared = offset.x * offset.x + offset.y * offset.y + offset.z * offset.z;
            if (squared <= bestSquared) {
                bestSquared = squared;
                best = DrawnPoint{index, entry.code, position, std::sqrt(squared)};
            }
        }
    }
    return best;
}

} // namespace omicron
