// FrameRateMeter: frames per second as the charts show them, from the frames' own times. The
// view draws on demand, so the rate counts the frames of the last second, and while the view
// has been drawing for less than that (the first frames of a preview, or the first after a
// pause) over the time since its first frame: the very first frames get a rate, and a pause
// does not dilute the rate of the frames that follow it.
#pragma once

#include <deque>

namespace omicron {

class FrameRateMeter {
public:
    static constexpr double kWindowSeconds = 1.0;
    // The shortest span a rate is taken over: one frame alone is not an infinite rate.
    static constexpr double kMinimumSpanSeconds = 0.1;

    // A frame was drawn at `seconds` (non-decreasing from call to call).
    void frameAt(double seconds);
    // Frames per second at `seconds` (not before the last frame): 0 once no frame was drawn
    // in the last second.
    double rateAt(double seconds);
    bool anyFrame() const { return m_activeSince >= 0.0; }
    void reset();

private:
    std::deque<double> m_frames; // the times of the frames of the last window
    double m_activeSince = -1.0; // the first frame after a pause of a window or more
};

} // namespace omicron
