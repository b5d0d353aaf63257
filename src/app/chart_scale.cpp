#include "chart_scale.hpp"

#include <QLocale>
#include <QStringList>
#include <algorithm>
#include <climits>
#include <cmath>

namespace omicron {

namespace {

// The step of 1, 2 or 5 times a power of ten that puts closest to `targetCount` ticks on a
// span (> 0), never fewer than two; of two as close, the larger step.
double roundStep(double span, int targetCount) {
    const double raw = span / std::max(1, targetCount - 1);
    const double power = std::pow(10.0, std::floor(std::log10(raw)));
    double best = 10.0 * power;
    int bestMiss = INT_MAX;
    for (const double mantissa : {10.0, 5.0, 2.0, 1.0}) {
        const double step = mantissa * power;
        const int ticks = static_cast<int>(std::floor(span / step + 1e-9)) + 1;
        const int miss = std::abs(ticks - targetCount) + (ticks < 2 ? 100 : 0);
        if (miss < bestMiss) {
            bestMiss = miss;
            best = step;
        }
    }
    return best;
}

// The divisor and suffix of an axis whose larger end is `largest`.
void chooseUnit(double largest, ChartUnit unit, AxisTicks& ticks) {
    const auto use = [&](double scale, const char* suffix) {
        ticks.scale = scale;
        ticks.suffix = QString::fromLatin1(suffix);
    };
    switch (unit) {
    case ChartUnit::Count:
        if (largest >= 1e9) {
            use(1e9, " G");
        } else if (largest >= 1e6) {
            use(1e6, " M");
        } else if (largest >= 1e4) {
            use(1e3, " k");
        }
        break;
    case ChartUnit::Milliseconds:
        largest >= 1000.0 ? use(1000.0, " s") : use(1.0, " ms");
        break;
    case ChartUnit::Mebibytes:
        largest >= 1024.0 ? use(1024.0, " GiB") : use(1.0, " MiB");
        break;
    case ChartUnit::Seconds:
        use(1.0, " s");
        ticks.unitAtZero = true;
        break;
    case ChartUnit::Rate:
        break;
    }
}

} // namespace

AxisTicks roundTicks(double min, double max, int targetCount, ChartUnit unit) {
    AxisTicks ticks;
    chooseUnit(std::max(std::abs(min), std::abs(max)), unit, ticks);
    const double low = min / ticks.scale;
    const double high = std::max(max / ticks.scale, low + 1e-9);
    const double step = roundStep(high - low, targetCount);
    for (double k = std::ceil(low / step - 1e-9); k * step <= high + step * 1e-9; k += 1.0) {
        ticks.values.push_back(k * step * ticks.scale);
    }
    ticks.step = step * ticks.scale;
    return ticks;
}

double roundAxisEnd(double value, int targetCount, ChartUnit unit) {
    if (!(value > 0.0)) {
        return 1.0;
    }
    const double step = roundTicks(0.0, value, targetCount, unit).step;
    return std::ceil(value / step - 1e-9) * step;
}

QStringList tickLabels(const AxisTicks& ticks) {
    const double scaledStep = ticks.step / ticks.scale;
    const int decimals =
        scaledStep >= 1.0 ? 0
                          : std::min(6, static_cast<int>(std::ceil(-std::log10(scaledStep) - 1e-9)));
    QStringList labels;
    for (const double value : ticks.values) {
        double scaled = value / ticks.scale;
        if (std::abs(scaled) < 0.5 * std::pow(10.0, -decimals)) {
            scaled = 0.0; // no "-0"
        }
        // A bare 0 needs no unit, except on the time axis, where "0 s" says what it counts.
        labels.append(scaled == 0.0 && !ticks.unitAtZero
                          ? QStringLiteral("0")
                          : QString::number(scaled, 'f', decimals) + ticks.suffix);
    }
    return labels;
}

QString exactValue(double value, ChartUnit unit) {
    const QLocale locale;
    switch (unit) {
    case ChartUnit::Count:
        return locale.toString(static_cast<qlonglong>(std::llround(value)));
    case ChartUnit::Mebibytes:
    case ChartUnit::Rate:
        return locale.toString(value, 'f', 1);
    case ChartUnit::Milliseconds:
    case ChartUnit::Seconds:
        return locale.toString(value, 'f', 2);
    }
    return locale.toString(value);
}

} // namespace omicron
