#include "scale_bar.hpp"

#include <algorithm>
#include <cmath>

namespace omicron {

ScaleBar scaleBarFor(double unitsPerPixel, double maxWidthPx) {
    ScaleBar bar;
    const double longest = unitsPerPixel * maxWidthPx;
    if (!(longest > 0.0) || !std::isfinite(longest)) {
        return bar;
    }
    const double power = std::pow(10.0, std::floor(std::log10(longest)));
    for (const double mantissa : {5.0, 2.0, 1.0}) {
        if (mantissa * power <= longest * (1.0 + 1e-9)) {
            bar.length = mantissa * power;
            break;
        }
    }
    bar.widthPx = bar.length / unitsPerPixel;
    const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(bar.length) + 1e-9)));
    bar.label = QString::number(bar.length, 'f', decimals);
    return bar;
}

} // namespace omicron
