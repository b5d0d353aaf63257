#include "time_series_chart.hpp"

#include <QChart>
#include <QContextMenuEvent>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QFont>
#include <QFontMetrics>
#include <QLineSeries>
#include <QMenu>
#include <QCategoryAxis>
#include <QCursor>
#include <QTextStream>
#include <QToolTip>
#include <algorithm>
#include <cmath>
#include <vector>

namespace omicron {

namespace {

// Labels an axis with round ticks over [from, to]: a category axis whose categories end on
// the ticks, labelled on their values (a plain value axis can only printf its labels).
// Qt Charts gives each label of a category axis an equal share of the axis (its length over
// the number of category bounds, less padding) and cuts longer ones to "...": no more ticks
// than the axis has room for (`maxCount`), fewer than the target if need be.
void setTicks(QCategoryAxis* axis, double from, double to, int targetCount, int maxCount,
              ChartUnit unit) {
    AxisTicks ticks = roundTicks(from, to, targetCount, unit);
    for (int target = targetCount - 1;
         static_cast<int>(ticks.values.size()) > maxCount && target >= 2; --target) {
        ticks = roundTicks(from, to, target, unit);
    }
    if (static_cast<int>(ticks.values.size()) > maxCount) {
        // Still too many: every k-th tick (multiples of a round step stay round enough).
        const std::size_t keepEvery =
            (ticks.values.size() + static_cast<std::size_t>(maxCount) - 1) /
            static_cast<std::size_t>(std::max(1, maxCount));
        std::vector<double> kept;
        for (std::size_t i = 0; i < ticks.values.size(); i += keepEvery) {
            kept.push_back(ticks.values[i]);
        }
        ticks.values = std::move(kept);
        ticks.step *= static_cast<double>(keepEvery);
    }
    const QStringList labels = tickLabels(ticks);
    for (const QString& label : axis->categoriesLabels()) {
        axis->remove(label);
    }
    // The first category starts just below the first tick, so that tick gets its label too.
    axis->setStartValue(ticks.values.empty() ? from : ticks.values.front() - ticks.step * 1e-6);
    for (std::size_t i = 0; i < ticks.values.size(); ++i) {
        axis->append(labels.at(static_cast<qsizetype>(i)), ticks.values[i]);
    }
    axis->setRange(from, to);
}

QCategoryAxis* makeAxis(QChart* chart, const QFont& font) {
    auto* axis = new QCategoryAxis(chart);
    axis->setLabelsPosition(QCategoryAxis::AxisLabelsPositionOnValue);
    axis->setLabelsFont(font);
    return axis;
}

// Ticks as many as their labels have room for: one per this many pixels of the plot area.
constexpr int kPixelsPerTimeTick = 48;
constexpr int kPixelsPerValueTick = 24;
constexpr int kGrowthTicks = 4; // the round steps an axis grows by

} // namespace

TimeSeriesChart::TimeSeriesChart(const QString& title, const QString& unit, ChartUnit scale,
                                 const QStringList& lineNames, QWidget* parent)
    : QChartView(parent), m_title(title), m_unit(unit), m_scale(scale) {
    auto* chart = new QChart();
    chart->setMargins(QMargins(2, 2, 2, 2));
    // With a fixed plot area (placePlotArea) Qt Charts lays the axes out again only when the
    // plot background is visible: a transparent one, so new tick labels get their room.
    chart->setPlotAreaBackgroundVisible(true);
    chart->setPlotAreaBackgroundBrush(Qt::NoBrush);
    chart->setPlotAreaBackgroundPen(Qt::NoPen);
    chart->setTitle(title);
    // Small panels: short labels in a small font; the units are in the tick labels.
    QFont smallFont = chart->font();
    smallFont.setPointSizeF(7.0);
    QFont titleFont = chart->titleFont();
    titleFont.setPointSizeF(8.0);
    titleFont.setBold(true);
    chart->setTitleFont(titleFont);
    chart->legend()->setVisible(lineNames.size() > 1);
    chart->legend()->setAlignment(Qt::AlignBottom);
    chart->legend()->setFont(smallFont);
    chart->legend()->setShowToolTips(true); // a name cut short shows whole on hover
    m_axisX = makeAxis(chart, smallFont);
    m_axisY = makeAxis(chart, smallFont);
    chart->addAxis(m_axisX, Qt::AlignBottom);
    chart->addAxis(m_axisY, Qt::AlignLeft);
    for (const QString& name : lineNames) {
        auto* series = new QLineSeries(chart);
        series->setName(name);
        chart->addSeries(series);
        series->attachAxis(m_axisX);
        series->attachAxis(m_axisY);
        connect(series, &QLineSeries::hovered, this,
                [this, series](const QPointF& point, bool state) {
                    showPointValue(series, point, state);
                });
        m_lines.push_back(series);
    }
    // QChartView made a chart of its own, which setChart() only releases: delete it.
    QChart* const defaultChart = QChartView::chart();
    setChart(chart);
    delete defaultChart;
    setRenderHint(QPainter::Antialiasing);
    setMinimumSize(200, 140);
    setToolTip(tr("%1 (%2). Hover a line for exact values; right-click to export the chart as "
                  "PNG or its data as CSV.")
                   .arg(title, unit));
    clear();
}

void TimeSeriesChart::append(int line, double seconds, double value) {
    QLineSeries* series = m_lines.at(static_cast<std::size_t>(line));
    if (series->count() >= kMaxSamples) {
        series->removePoints(0, series->count() - kMaxSamples + 1);
    }
    series->append(seconds, value);
    growAxes(seconds, value);
}

void TimeSeriesChart::setLine(int line, const QList<QPointF>& points) {
    m_lines.at(static_cast<std::size_t>(line))->replace(points);
    for (const QPointF& point : points) {
        growAxes(point.x(), point.y());
    }
}

void TimeSeriesChart::clear() {
    for (QLineSeries* series : m_lines) {
        series->clear();
    }
    m_maxValue = 1.0;
    if (!m_sharedTime) {
        m_timeFrom = 0.0;
        m_timeTo = 1.0;
    }
    updateTicks();
}

void TimeSeriesChart::setTimeRange(double fromSeconds, double toSeconds) {
    m_sharedTime = true;
    if (fromSeconds != m_timeFrom || toSeconds != m_timeTo) {
        m_timeFrom = fromSeconds;
        m_timeTo = toSeconds;
        updateTicks();
    }
}

double TimeSeriesChart::timeFrom() const {
    return m_timeFrom;
}

double TimeSeriesChart::timeTo() const {
    return m_timeTo;
}

QStringList TimeSeriesChart::axisLabels() const {
    return m_axisX->categoriesLabels() + m_axisY->categoriesLabels();
}

void TimeSeriesChart::resizeEvent(QResizeEvent* event) {
    QChartView::resizeEvent(event);
    placePlotArea();
    updateTicks();
}

void TimeSeriesChart::updateTicks() {
    const QRectF area = chart()->plotArea();
    const int timeTicks = std::clamp(static_cast<int>(area.width()) / kPixelsPerTimeTick, 2, 8);
    const int valueTicks =
        std::clamp(static_cast<int>(area.height()) / kPixelsPerValueTick, 2, 5);
    // Room for whole labels: Qt gives each label the axis length over 1 + ticks, less twice
    // its label padding (5 px); a value label needs its text's height, a time label the
    // width of the widest one ("000.0 s").
    constexpr int kLabelPadding = 5;
    const QFontMetrics metrics(m_axisY->labelsFont());
    const int valueRoom =
        static_cast<int>(area.height()) / (metrics.height() + 2 * kLabelPadding) - 1;
    const int timeRoom =
        static_cast<int>(area.width()) /
            (metrics.horizontalAdvance(QStringLiteral("000.0 s")) + 2 * kLabelPadding) -
        1;
    setTicks(m_axisX, m_timeFrom, m_timeTo, timeTicks, std::max(1, timeRoom), ChartUnit::Seconds);
    setTicks(m_axisY, 0.0, m_maxValue, valueTicks, std::max(1, valueRoom), m_scale);
}

void TimeSeriesChart::placePlotArea() {
    const QFontMetrics labels(m_axisY->labelsFont());
    const QFontMetrics title(chart()->titleFont());
    const QFontMetrics legend(chart()->legend()->font());
    // Room on the left for the widest label an axis of this unit writes ("1.5 GiB").
    const int left = labels.horizontalAdvance(QStringLiteral("000.0 GiB")) + 14;
    const int top = title.height() + 16;
    const int bottom = labels.height() + 14 +
                       (chart()->legend()->isVisible() ? legend.height() + 20 : 0);
    const QRectF area(left, top, std::max(10, width() - left - 14),
                      std::max(10, height() - top - bottom));
    chart()->setPlotArea(area);
}

void TimeSeriesChart::growAxes(double seconds, double value) {
    // Axes only grow, to a round value with room to spare, so a live chart does not jitter
    // every sample and its last tick is labelled.
    bool grown = false;
    if (!m_sharedTime && seconds > m_timeTo) {
        m_timeTo = roundAxisEnd(seconds * 1.2, kGrowthTicks, ChartUnit::Seconds);
        grown = true;
    }
    if (value > m_maxValue) {
        m_maxValue = roundAxisEnd(value * 1.1, kGrowthTicks, m_scale);
        grown = true;
    }
    if (grown) {
        updateTicks();
    }
}

void TimeSeriesChart::showPointValue(const QLineSeries* series, const QPointF& point,
                                     bool hovered) {
    if (!hovered) {
        QToolTip::hideText();
        return;
    }
    // The sample nearest the pointer on this line (the hover point lies between samples).
    const QList<QPointF> points = series->points();
    const auto nearest = std::min_element(points.begin(), points.end(),
                                          [&](const QPointF& a, const QPointF& b) {
                                              return std::abs(a.x() - point.x()) <
                                                     std::abs(b.x() - point.x());
                                          });
    if (nearest == points.end()) {
        return;
    }
    QToolTip::showText(QCursor::pos(),
                       tr("%1 at %2 s: %3 %4")
                           .arg(series->name(), exactValue(nearest->x(), ChartUnit::Seconds),
                                exactValue(nearest->y(), m_scale), m_unit),
                       this);
}

bool TimeSeriesChart::exportPng(const QString& path, QString* error) {
    const QPixmap picture = grab();
    if (picture.isNull() || !picture.save(path, "PNG")) {
        if (error != nullptr) {
            *error = tr("%1: cannot write the chart picture (PNG)").arg(path);
        }
        return false;
    }
    return true;
}

bool TimeSeriesChart::exportCsv(const QString& path, QString* error) const {
    QFile file(path);
    if (!file.open(QIODevice::WriteOnly | QIODevice::Truncate | QIODevice::Text)) {
        if (error != nullptr) {
            *error = tr("%1: cannot open for writing: %2").arg(path, file.errorString());
        }
        return false;
    }
    // Long format (one row per sample): the lines have their own sample times.
    QTextStream out(&file);
    out << "chart,line,time_s,value\n";
    for (const QLineSeries* series : m_lines) {
        const QList<QPointF> points = series->points();
        for (const QPointF& point : points) {
            out << '"' << m_title << "\",\"" << series->name() << "\"," << point.x() << ','
                << point.y() << '\n';
        }
    }
    out.flush();
    if (file.error() != QFile::NoError) {
        if (error != nullptr) {
            *error = tr("%1: write failed: %2").arg(path, file.errorString());
        }
        return false;
    }
    return true;
}

void TimeSeriesChart::contextMenuEvent(QContextMenuEvent* event) {
    QMenu menu(this);
    QAction* png = menu.addAction(tr("Export Chart as PNG…"));
    menu.addAction(tr("Export Data as CSV…"));
    QAction* chosen = menu.exec(event->globalPos());
    if (chosen == nullptr) {
        return;
    }
    const bool asPng = chosen == png;
    const QString suggested = m_title.toLower().replace(QLatin1Char(' '), QLatin1Char('-')) +
                              (asPng ? QStringLiteral(".png") : QStringLiteral(".csv"));
    const QString path =
        QFileDialog::getSaveFileName(this, chosen->text(), suggested,
                                     asPng ? tr("PNG images (*.png)") : tr("CSV files (*.csv)"));
    if (path.isEmpty()) {
        return;
    }
    QString error;
    if (!(asPng ? exportPng(path, &error) : exportCsv(path, &error))) {
        emit exportFailed(path, error);
    }
}

} // namespace omicron
