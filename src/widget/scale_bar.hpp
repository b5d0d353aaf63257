// The view's scale bar: the longest round length (1, 2 or 5 times a power of ten, in the
// file's units) that fits a given width on screen at the pivot's depth.
#pragma once

#include <QString>

namespace omicron {

struct ScaleBar {
    double length = 0.0; // file units
    double widthPx = 0.0;
    QString label;       // "50", "0.2", "2000"
};

// `unitsPerPixel` > 0: file units one pixel covers at the pivot.
ScaleBar scaleBarFor(double unitsPerPixel, double maxWidthPx);

} // namespace omicron
