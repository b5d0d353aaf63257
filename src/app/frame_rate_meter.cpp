#include "frame_rate_meter.hpp"

#include <algorithm>

namespace omicron {

void FrameRateMeter::frameAt(double seconds) {
    if (m_frames.empty() || seconds - m_frames.back() >= kWindowSeconds) {
        m_activeSince = seconds;
    }
    m_frames.push_back(seconds);
}

double FrameRateMeter::rateAt(double seconds) {
    while (!m_frames.empty() && m_frames.front() <= seconds - kWindowSeconds) {
        m_frames.pop_front();
    }
    if (m_frames.empty()) {
        return 0.0;
    }
    const double span =
        std::clamp(seconds - m_activeSince, kMinimumSpanSeconds, kWindowSeconds);
    return static_cast<double>(m_frames.size()) / span;
}

void FrameRateMeter::reset() {
    m_frames.clear();
    m_activeSince = -1.0;
}

} // namespace omicron
