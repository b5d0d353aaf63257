// Timing helpers shared by the benchmarks: wall-clock seconds, best of N runs, quantiles.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <vector>

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

// The q-quantile of `values` (q = 0.5: the median; the upper one of an even count); 0 when
// there are none.
template <typename T> double quantile(std::vector<T> values, double q) {
    if (values.empty()) {
        return 0.0;
    }
    const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * values.size()));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    return static_cast<double>(values[k]);
}

} // namespace omicron::bench
