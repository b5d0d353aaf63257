#include "build/build_statistics.hpp"

namespace omicron {

std::uint64_t BuildStatistics::totalNodes() const {
    std::uint64_t total = 0;
    for (const LevelStatistics& level : levels) {
        total += level.nodes;
    }
    return total;
}

void recordMilestones(std::array<double, 10>& milestones, std::uint64_t inserted,
                      std::uint64_t total, double seconds) {
    for (std::size_t decile = 0; decile < milestones.size(); ++decile) {
        // inserted / total >= (decile + 1) / 10, in integers.
        if (milestones[decile] < 0.0 && total > 0 && inserted * 10 >= total * (decile + 1)) {
            milestones[decile] = seconds;
        }
    }
}

} // namespace omicron
