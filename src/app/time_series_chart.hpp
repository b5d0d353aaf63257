// TimeSeriesChart: one live line chart of the charts panel (Qt Charts), value over seconds
// since the open, with a bounded number of samples per line, axes labelled in human units at
// round values (chart_scale), a tooltip with the exact value of a hovered point, and export
// of the picture (PNG) and the data (CSV) from its context menu or from code.
#pragma once

#include "chart_scale.hpp"

#include <QChartView>
#include <QString>
#include <QStringList>
#include <vector>

class QCategoryAxis;
class QLineSeries;

namespace omicron {

class TimeSeriesChart : public QChartView {
    Q_OBJECT
public:
    // Samples kept per line: at 10 Hz, the last 10 minutes, so a long session stays cheap.
    static constexpr int kMaxSamples = 6000;

    // `unit` names what the values count ("points", "ms"), for the title and tooltips;
    // `scale` decides how the value axis is labelled. Line names are short (legends stay
    // whole in a small panel); the chart's tooltip explains them.
    TimeSeriesChart(const QString& title, const QString& unit, ChartUnit scale,
                    const QStringList& lineNames, QWidget* parent = nullptr);

    QString title() const { return m_title; }
    int lineCount() const { return static_cast<int>(m_lines.size()); }
    QLineSeries* line(int index) const { return m_lines.at(static_cast<std::size_t>(index)); }

    void append(int line, double seconds, double value);
    // The time axis shown, shared by the charts of a panel so the same moment sits at the same
    // place in each. Until it is called the time axis grows with the samples.
    void setTimeRange(double fromSeconds, double toSeconds);
    double timeFrom() const;
    double timeTo() const;
    // The labels the axes show now (time axis, then value axis), for tests.
    QStringList axisLabels() const;
    // Replaces a line by the given points (used for reference lines such as the ideal rate).
    void setLine(int line, const QList<QPointF>& points);
    void clear();

    // Throw nothing: return false and fill `error` (with the file name) on failure.
    bool exportPng(const QString& path, QString* error = nullptr);
    bool exportCsv(const QString& path, QString* error = nullptr) const;

signals:
    // A PNG or CSV export from the context menu failed (the window shows the dialog).
    void exportFailed(const QString& path, const QString& message);

protected:
    void contextMenuEvent(QContextMenuEvent* event) override;
    void resizeEvent(QResizeEvent* event) override;

private:
    void growAxes(double seconds, double value);
    // The plot area at the same place in every chart of a size, whatever the width of the
    // value labels: charts stacked in a column share their time axis pixel for pixel.
    void placePlotArea();
    // Round ticks on both axes, as many as the plot area has room for.
    void updateTicks();
    void showPointValue(const QLineSeries* series, const QPointF& point, bool hovered);

    QString m_title;
    QString m_unit;
    ChartUnit m_scale;
    std::vector<QLineSeries*> m_lines;
    QCategoryAxis* m_axisX = nullptr;
    QCategoryAxis* m_axisY = nullptr;
    bool m_sharedTime = false; // setTimeRange() decides the time axis
    double m_maxValue = 1.0;
    // The time axis shown: set by setTimeRange, or grown by the samples until it is called.
    double m_timeFrom = 0.0;
    double m_timeTo = 1.0;
};

} // namespace omicron
