// Timing helpers shared by the benchmarks: wall-clock seconds, best of N runs.
#pragma once

#include <algorithm>
#include <chrono>

namespace omicron::bench {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Best of `runs` timings of fn(); reset() (untimed) restores its input before each run.
template <typename Reset, typename Fn> double bestSeconds(int runs, Reset&& reset, Fn&& fn) {
    double best = 1e30;
    for (int i = 0; i < runs; ++i) {
        reset();
        const auto start = Clock::now();
        fn();
        best = std::min(best, secondsSince(start));
    }
    return best;
}

template <typename Fn> double bestSeconds(int runs, Fn&& fn) {
    return bestSeconds(
        runs, [] {}, fn);
}

} // namespace omicron::bench
