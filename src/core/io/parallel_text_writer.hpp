// Text output (XYZ, ascii PLY) formatted on every core: numbers to decimal text (to_chars, about
// 100 ns a point) are all of a text writer's work, and a loop over the points ran it on one.
#pragma once

#include "io/atomic_file_writer.hpp"

#include <algorithm>
#include <cstddef>
#include <string>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <vector>

namespace omicron {

// Points [0, count) cut into chunks of `chunkPoints`: a group of chunks (8 a core) is formatted
// at once, each by `format(begin, end, text)` appending the text of points [begin, end) to
// `text` (empty on the call) on oneTBB's threads, then written to `out` in order on the calling
// thread. The file is the same as a loop over the points would write.
template <typename Format>
void writeTextInParallel(AtomicFileWriter& out, std::size_t count, std::size_t chunkPoints,
                         Format&& format) {
    chunkPoints = std::max<std::size_t>(chunkPoints, 1);
    const std::size_t groupChunks =
        8 * static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    std::vector<std::string> texts(groupChunks);
    for (std::size_t groupStart = 0; groupStart < count; groupStart += groupChunks * chunkPoints) {
        const std::size_t chunks =
            std::min(groupChunks, (count - groupStart + chunkPoints - 1) / chunkPoints);
        tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
            const std::size_t begin = groupStart + c * chunkPoints;
            texts[c].clear();
            format(begin, std::min(count, begin + chunkPoints), texts[c]);
        });
        for (std::size_t c = 0; c < chunks; ++c) {
            out.write(texts[c]);
        }
    }
}

} // namespace omicron
