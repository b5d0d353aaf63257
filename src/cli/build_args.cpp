#include "build_args.hpp"

#include <cstdlib>

namespace omicron::cli {

namespace {

LeafCollapse parseCollapse(const std::string& text) {
    if (text == "off") {
        return LeafCollapse::Off;
    }
    if (text == "lossless") {
        return LeafCollapse::Lossless;
    }
    if (text == "paper") {
        return LeafCollapse::Paper;
    }
    throw UsageError("--collapse takes off, lossless or paper, found '" + text + "'");
}

double parseRatio(const std::string& text) {
    char* end = nullptr;
    const double ratio = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !(ratio > 0.0 && ratio <= 1.0)) {
        throw UsageError("--ratio takes a number in (0, 1], found '" + text + "'");
    }
    return ratio;
}

} // namespace

BuildArgs buildArgs(const ParsedArgs& parsed) {
    BuildArgs args;
    if (const auto depth = parsed.value("depth")) {
        args.options.maxLevel =
            static_cast<int>(parseInteger(*depth, "depth", 1, morton::kMaxLevel));
    }
    if (const auto ratio = parsed.value("ratio")) {
        args.options.ratio = parseRatio(*ratio);
    }
    if (const auto worklist = parsed.value("worklist")) {
        args.options.worklistSize = parseInteger(*worklist, "worklist", 1, 1 << 20);
    }
    if (const auto collapse = parsed.value("collapse")) {
        args.options.collapse = parseCollapse(*collapse);
    }
    args.threads = threadsOption(parsed);
    args.options.threads = args.threads;
    args.sortChunks = sortChunksOption(parsed);
    if (const auto store = parsed.value("store");
        store && !parsePointStorage(*store, args.storage)) {
        throw UsageError("--store takes exact or packed, found '" + *store + "'");
    }
    return args;
}

} // namespace omicron::cli
