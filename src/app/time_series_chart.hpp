// TimeSeriesChart: one live line chart of the charts panel (Qt Charts), value over seconds
// since the build started, with a bounded number of samples per line, and export of the
// picture (PNG) and the data (CSV) from its context menu or from code.
#pragma once

#include <QChartView>
#include <QString>
#include <QStringList>
#include <vector>

class QLineSeries;
class QValueAxis;

namespace omicron {

class TimeSeriesChart : public QChartView {
    Q_OBJECT
public:
    // Samples kept per line: at 10 Hz, the last 10 minutes, so a long session stays cheap.
    static constexpr int kMaxSamples = 6000;

    TimeSeriesChart(const QString& title, const QString& unit, const QStringList& lineNames,
                    QWidget* parent = nullptr);

    QString title() const { return m_title; }
    int lineCount() const { return static_cast<int>(m_lines.size()); }
    QLineSeries* line(int index) const { return m_lines.at(static_cast<std::size_t>(index)); }

    void append(int line, double seconds, double value);
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

private:
    void growAxes(double seconds, double value);

    QString m_title;
    QString m_unit;
    std::vector<QLineSeries*> m_lines;
    QValueAxis* m_axisX = nullptr;
    QValueAxis* m_axisY = nullptr;
    double m_maxSeconds = 1.0;
    double m_maxValue = 1.0;
};

} // namespace omicron
