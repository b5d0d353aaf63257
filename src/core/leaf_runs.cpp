#include "leaf_runs.hpp"

#include <algorithm>
#include <cassert>

namespace omicron {

std::size_t endOfRun(std::span<const morton::Code> codes, std::size_t begin, std::size_t end,
                     int shift) {
    assert(begin < end);
    const morton::Code key = codes[begin] >> shift;
    // Gallop: runs are often long (dense leaves), sometimes a single point.
    std::size_t low = begin + 1; // first index not yet known to be in the run
    std::size_t step = 1;
    while (low + step - 1 < end && (codes[low + step - 1] >> shift) == key) {
        low += step;
        step *= 2;
    }
    const std::size_t high = std::min(end, low + step - 1);
    const auto first = codes.begin() + static_cast<std::ptrdiff_t>(low);
    const auto last = codes.begin() + static_cast<std::ptrdiff_t>(high);
    return static_cast<std::size_t>(
        std::partition_point(first, last, [&](morton::Code c) { return (c >> shift) == key; }) -
        codes.begin());
}

void findLeafRuns(std::span<const morton::Code> codes, std::size_t begin, std::size_t end,
                  int maxLevel, std::vector<LeafRun>& runs) {
    const int shift = 3 * (morton::kMaxLevel - maxLevel);
    while (begin < end) {
        const std::size_t runEnd = endOfRun(codes, begin, end, shift);
        runs.push_back({codes[begin] >> shift, static_cast<std::uint32_t>(begin),
                        static_cast<std::uint32_t>(runEnd - begin)});
        begin = runEnd;
    }
}

std::size_t insertableEnd(std::span<const morton::Code> codes, std::size_t begin,
                          std::size_t available, bool inputEnded, int groupShift,
                          std::size_t limit) {
    if (begin >= available) {
        return begin;
    }
    const std::size_t window = std::min(available, begin + std::max<std::size_t>(limit, 1));
    if (window == available && inputEnded) {
        return available;
    }
    // Hold back the group the window ends in: it may continue after the window.
    const morton::Code lastKey = codes[window - 1] >> groupShift;
    const auto first = codes.begin() + static_cast<std::ptrdiff_t>(begin);
    const auto last = codes.begin() + static_cast<std::ptrdiff_t>(window);
    const auto groupStart = std::partition_point(
        first, last, [&](morton::Code c) { return (c >> groupShift) < lastKey; });
    if (groupStart != first) {
        return static_cast<std::size_t>(groupStart - codes.begin());
    }
    // The window holds a single group: take all of it once its end is known.
    const std::size_t groupEnd = endOfRun(codes, begin, available, groupShift);
    return groupEnd < available || inputEnded ? groupEnd : begin;
}

} // namespace omicron
