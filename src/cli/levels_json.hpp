// The "levels" array of `build --json` and `info FILE.omh --json`: one writer, so the two
// commands print the same shape and a script can compare them.
#pragma once

#include "json_writer.hpp"

#include <cstdint>

namespace omicron::cli {

// `levels`: indexable by level, each with nodes, leaves and points (LevelStatistics or the
// .omh level table).
template <typename Levels> void writeLevelsJson(JsonWriter& json, const Levels& levels) {
    json.key("levels").beginArray();
    for (std::size_t level = 0; level < levels.size(); ++level) {
        json.beginObject();
        json.key("level").value(static_cast<std::uint64_t>(level));
        json.key("nodes").value(static_cast<std::uint64_t>(levels[level].nodes));
        json.key("leaves").value(static_cast<std::uint64_t>(levels[level].leaves));
        json.key("points").value(static_cast<std::uint64_t>(levels[level].points));
        json.endObject();
    }
    json.endArray();
}

} // namespace omicron::cli
