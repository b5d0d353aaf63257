// Chart axes a person reads at a glance: round tick values (1, 2 or 5 times a power of ten)
// and labels in human units — "24.2 M" points, "1.4 GiB", "250 ms", "12 s" — instead of
// printf's "2.42e+07". Pure functions of the axis range, so tests check them without a chart.
#pragma once

#include <QString>
#include <vector>

namespace omicron {

// What a chart's numbers are, which decides how they are written.
enum class ChartUnit {
    Count,        // points, nodes: 950, 8.1 k, 24.2 M, 1.05 G
    Milliseconds, // 16 ms, 250 ms; 1.5 s from a second up
    Mebibytes,    // values in MiB: 512 MiB; 1.4 GiB from a GiB up
    Seconds,      // the time axis: 0 s, 2.5 s, 90 s
    Rate,         // frames per second: 0, 30, 60
};

struct AxisTicks {
    double step = 1.0;          // between two ticks, in the chart's values
    std::vector<double> values; // the multiples of `step` in [min, max], ascending
    double scale = 1.0;         // the labels show value / scale ...
    QString suffix;             // ... followed by this (" M", " GiB", " ms")
    bool unitAtZero = false;    // "0 s" on the time axis; elsewhere a bare "0"
};

// About `targetCount` ticks covering [min, max] (both finite), round in the unit the labels
// use: one prefix for the whole axis, from the larger end (so a MiB axis past a GiB gets
// ticks at 0.5 GiB steps, not at 500 MiB).
AxisTicks roundTicks(double min, double max, int targetCount, ChartUnit unit);

// Where an axis from 0 that must show `value` ends: the first of its round ticks (as
// roundTicks would place about `targetCount` of them) at or above `value`, so its last tick
// is labelled and it grows in round steps.
double roundAxisEnd(double value, int targetCount, ChartUnit unit);

// The tick labels: just enough decimals that neighbouring ticks differ.
QStringList tickLabels(const AxisTicks& ticks);

// One value written exactly (without its unit), for tooltips: "24,213,457" points,
// "12.46" ms, "1,423.5" MiB, "12.40" s.
QString exactValue(double value, ChartUnit unit);

} // namespace omicron
