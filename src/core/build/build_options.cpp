#include "build/build_options.hpp"

#include <stdexcept>

namespace omicron {

const char* toString(LeafCollapse collapse) {
    switch (collapse) {
    case LeafCollapse::Off:
        return "off";
    case LeafCollapse::Lossless:
        return "lossless";
    case LeafCollapse::Paper:
        return "paper";
    }
    return "?";
}

void validate(const BuildOptions& options) {
    if (options.maxLevel < 1 || options.maxLevel > morton::kMaxLevel) {
        throw std::invalid_argument("depth must be in 1.." + std::to_string(morton::kMaxLevel) +
                                    ", got " + std::to_string(options.maxLevel));
    }
    if (!(options.ratio > 0.0 && options.ratio <= 1.0)) {
        throw std::invalid_argument("ratio must be in (0, 1], got " +
                                    std::to_string(options.ratio));
    }
    if (options.worklistSize == 0) {
        throw std::invalid_argument("worklist size must be at least 1, got 0");
    }
    if (options.threads < 0) {
        throw std::invalid_argument("threads must be 0 (all cores) or more, got " +
                                    std::to_string(options.threads));
    }
}

} // namespace omicron
