// LAZ predicts a coordinate difference by the median of the last five differences in the same
// return context. This is LASzip's approximate running median of five: it keeps five sorted
// values and, alternately, replaces one from the low or the high end, so its answer is part of
// the format and must be reproduced exactly, not replaced by a true median.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

namespace omicron::laz {

class StreamingMedian5 {
public:
    std::int32_t median() const { return m_values[2]; }
    // The five values, sorted (for tests).
    const std::array<std::int32_t, 5>& values() const { return m_values; }

    // Replacing at the high end drops the largest value and inserts `value` in order; at the
    // low end, the smallest. Both are done without a branch (a coordinate difference falls
    // anywhere among the five, so branches on it would be mispredicted): element i of a sorted
    // s[0..3] with `value` inserted is max(s[i-1], min(s[i], value)).
    void add(std::int32_t value) {
        std::array<std::int32_t, 5>& v = m_values;
        const bool high = m_replaceHigh;
        const std::int32_t s0 = high ? v[0] : v[1];
        const std::int32_t s1 = high ? v[1] : v[2];
        const std::int32_t s2 = high ? v[2] : v[3];
        const std::int32_t s3 = high ? v[3] : v[4];
        // LASzip's switch: replacing at the high end, a value not below the middle switches
        // to the low end; replacing at the low end, a value not above it to the high end.
        m_replaceHigh = value < v[2] || (!high && value == v[2]);
        v[0] = std::min(s0, value);
        v[1] = std::max(s0, std::min(s1, value));
        v[2] = std::max(s1, std::min(s2, value));
        v[3] = std::max(s2, std::min(s3, value));
        v[4] = std::max(s3, value);
    }

private:
    std::array<std::int32_t, 5> m_values{};
    bool m_replaceHigh = true;
};

} // namespace omicron::laz
