#include "build/leaf_runs.hpp"

#include "points/unit_cell_box.hpp"

#include <algorithm>
#include <cassert>
#include <optional>
#include <tbb/parallel_for.h>

namespace omicron {

namespace {

// Points scanned per parallel block of findLeafRuns.
constexpr std::size_t kRunBlockPoints = std::size_t{1} << 15;

morton::Code codeAt(const glm::vec3& p, int level) {
    return morton::encodeUnit(p.x, p.y, p.z) >> (3 * (morton::kMaxLevel - level));
}

// The first index in [low, high) whose point fails `inside` (points that pass come first).
template <typename Positions, typename Inside>
std::size_t partitionPoint(const Positions& positions, std::size_t low, std::size_t high,
                           Inside inside) {
    while (low < high) {
        const std::size_t middle = low + (high - low) / 2;
        if (inside(positions[middle])) {
            low = middle + 1;
        } else {
            high = middle;
        }
    }
    return low;
}

// Appends to `runs` a run (its code at `level` and first index; its count is left to the caller)
// for every index i in [begin, end) where one starts: i == first, or the cell of i differs from
// the cell of i - 1.
// A block of the index whose next entry is still in the current cell holds no start and is
// skipped unread; in the others, each start is found by binary search (the points in the
// current cell come first). Those blocks are prefetched whole a few dozen blocks ahead, as the
// index tells which they are. Measured on autzen_south's 4.8M points at depth 7: 2.2-2.5 ms on
// one thread, 0.9-1.0 ms on two; probing every 16th position instead (all lines read) took
// 2.4-3.0 / 1.4-1.9 ms.
template <typename Positions>
void appendRunStarts(const Positions& positions, BlockCodes index, std::size_t first,
                     std::size_t begin, std::size_t end, int level, std::vector<LeafRun>& runs) {
    constexpr std::size_t kPrefetchBlocks = 32;
    const int shift = 3 * (morton::kMaxLevel - level);
    // The index's cell for block k's first point; none past the index's end.
    const auto indexedCell = [&](std::size_t block) {
        return block < index.size() ? std::optional(index[block] >> shift) : std::nullopt;
    };
    std::size_t i = begin;
    UnitCellBox current{};
    morton::Code cell = 0;
    const auto startRun = [&](std::size_t at) {
        current = UnitCellBox::of(positions[at], level);
        cell = codeAt(positions[at], level);
        runs.push_back({cell, static_cast<std::uint32_t>(at), 0});
    };
    if (begin == first) {
        startRun(begin);
        ++i;
    } else {
        current = UnitCellBox::of(positions[i - 1], level);
        cell = codeAt(positions[i - 1], level);
    }
    while (i < end) {
        const std::size_t block = i / kBlockCodePoints;
        const std::size_t ahead = block + kPrefetchBlocks;
        if (ahead + 1 < index.size() && (index[ahead] >> shift) != (index[ahead + 1] >> shift)) {
            positions.prefetch(ahead * kBlockCodePoints, kBlockCodePoints);
        }
        const std::size_t next = (block + 1) * kBlockCodePoints;
        if (indexedCell(block + 1) == cell) {
            i = next; // [i, next] is in the current cell
            continue;
        }
        const std::size_t blockEnd = std::min(end, next);
        while (i < blockEnd) {
            i = partitionPoint(positions, i, blockEnd,
                               [&](const glm::vec3& p) { return current.contains(p); });
            if (i == blockEnd) {
                break;
            }
            startRun(i);
            i = indexedCell(block + 1) == cell ? blockEnd : i + 1;
        }
    }
}

} // namespace

template <PositionView Positions>
std::size_t endOfRun(const Positions& positions, std::size_t begin, std::size_t end, int level) {
    assert(begin < end);
    const UnitCellBox cell = UnitCellBox::of(positions[begin], level);
    // Gallop: runs are often long (dense leaves), sometimes a single point.
    std::size_t low = begin + 1; // first index not yet known to be in the run
    std::size_t step = 1;
    while (low + step - 1 < end && cell.contains(positions[low + step - 1])) {
        low += step;
        step *= 2;
    }
    const std::size_t high = std::min(end, low + step - 1);
    return partitionPoint(positions, low, high,
                          [&](const glm::vec3& p) { return cell.contains(p); });
}

template <PositionView Positions>
std::size_t startOfRun(const Positions& positions, std::size_t last, int level) {
    const UnitCellBox cell = UnitCellBox::of(positions[last], level);
    // Gallop towards the front: `high` is the lowest index known to be in the run.
    std::size_t high = last;
    std::size_t step = 1;
    while (high >= step && cell.contains(positions[high - step])) {
        high -= step;
        step *= 2;
    }
    const std::size_t low = high >= step ? high - step + 1 : 0;
    return partitionPoint(positions, low, high,
                          [&](const glm::vec3& p) { return !cell.contains(p); });
}

template <PositionView Positions>
void findLeafRuns(const Positions& positions, BlockCodes index, std::size_t begin,
                  std::size_t end, int maxLevel, std::vector<LeafRun>& runs) {
    if (begin >= end) {
        return;
    }
    const std::size_t blocks = (end - begin + kRunBlockPoints - 1) / kRunBlockPoints;
    // Each block lists the runs starting in it on its own (in parallel when there are several);
    // joined in block order, each run ends where the next one starts.
    std::vector<std::vector<LeafRun>> blockRuns(blocks);
    const auto scanBlock = [&](std::size_t block) {
        const std::size_t blockBegin = begin + block * kRunBlockPoints;
        std::vector<LeafRun> found; // filled locally: no shared cache lines
        appendRunStarts(positions, index, begin, blockBegin,
                        std::min(end, blockBegin + kRunBlockPoints), maxLevel, found);
        blockRuns[block] = std::move(found);
    };
    if (blocks == 1) {
        scanBlock(0);
    } else {
        tbb::parallel_for(std::size_t{0}, blocks, scanBlock);
    }
    const std::size_t first = runs.size();
    for (const std::vector<LeafRun>& found : blockRuns) {
        runs.insert(runs.end(), found.begin(), found.end());
    }
    for (std::size_t r = first; r < runs.size(); ++r) {
        const std::size_t runEnd = r + 1 < runs.size() ? runs[r + 1].begin : end;
        runs[r].count = static_cast<std::uint32_t>(runEnd - runs[r].begin);
    }
}

template <PositionView Positions>
std::size_t insertableEnd(const Positions& positions, std::size_t begin, std::size_t available,
                          bool inputEnded, int groupLevel, std::size_t limit) {
    if (begin >= available) {
        return begin;
    }
    const std::size_t window = std::min(available, begin + std::max<std::size_t>(limit, 1));
    if (window == available && inputEnded) {
        return available;
    }
    // Hold back the group the window ends in: it may continue after the window.
    const morton::Code lastGroup = codeAt(positions[window - 1], groupLevel);
    const std::size_t groupStart = partitionPoint(
        positions, begin, window,
        [&](const glm::vec3& p) { return codeAt(p, groupLevel) < lastGroup; });
    if (groupStart != begin) {
        return groupStart;
    }
    // The window holds a single group: take all of it once its end is known.
    const std::size_t groupEnd = endOfRun(positions, begin, available, groupLevel);
    return groupEnd < available || inputEnded ? groupEnd : begin;
}

#define OMICRON_LEAF_RUNS_INSTANTIATE(Positions)                                                 \
    template std::size_t endOfRun(const Positions&, std::size_t, std::size_t, int);             \
    template std::size_t startOfRun(const Positions&, std::size_t, int);                        \
    template void findLeafRuns(const Positions&, BlockCodes, std::size_t, std::size_t, int,     \
                               std::vector<LeafRun>&);                                          \
    template std::size_t insertableEnd(const Positions&, std::size_t, std::size_t, bool, int,   \
                                       std::size_t);
OMICRON_LEAF_RUNS_INSTANTIATE(ExactPositions)
OMICRON_LEAF_RUNS_INSTANTIATE(PackedPositions)

} // namespace omicron
