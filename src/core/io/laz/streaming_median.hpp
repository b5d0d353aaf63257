// LAZ predicts a coordinate difference by the median of the last five differences in the same
// return context. This is LASzip's approximate running median of five: it keeps five sorted
// values and, alternately, replaces one from the low or the high end, so its answer is part of
// the format and must be reproduced exactly, not replaced by a true median.
#pragma once

#include <array>
#include <cstdint>

namespace omicron::laz {

class StreamingMedian5 {
public:
    std::int32_t median() const { return m_values[2]; }

    void add(std::int32_t value) {
        std::array<std::int32_t, 5>& v = m_values;
        if (m_replaceHigh) {
            if (value < v[2]) { // shift the top two up, insert below the middle
                v[4] = v[3];
                v[3] = v[2];
                if (value < v[0]) {
                    v[2] = v[1];
                    v[1] = v[0];
                    v[0] = value;
                } else if (value < v[1]) {
                    v[2] = v[1];
                    v[1] = value;
                } else {
                    v[2] = value;
                }
            } else {
                if (value < v[3]) {
                    v[4] = v[3];
                    v[3] = value;
                } else {
                    v[4] = value;
                }
                m_replaceHigh = false;
            }
        } else {
            if (v[2] < value) { // shift the bottom two down, insert above the middle
                v[0] = v[1];
                v[1] = v[2];
                if (v[4] < value) {
                    v[2] = v[3];
                    v[3] = v[4];
                    v[4] = value;
                } else if (v[3] < value) {
                    v[2] = v[3];
                    v[3] = value;
                } else {
                    v[2] = value;
                }
            } else {
                if (v[1] < value) {
                    v[0] = v[1];
                    v[1] = value;
                } else {
                    v[0] = value;
                }
                m_replaceHigh = true;
            }
        }
    }

private:
    std::array<std::int32_t, 5> m_values{};
    bool m_replaceHigh = true;
};

} // namespace omicron::laz
