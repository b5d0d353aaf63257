#include "time_series_chart.hpp"

#include <QChart>
#include <QContextMenuEvent>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QFont>
#include <QLineSeries>
#include <QMenu>
#include <QTextStream>
#include <QValueAxis>
#include <algorithm>

namespace omicron {

TimeSeriesChart::TimeSeriesChart(const QString& title, const QString& unit,
                                 const QStringList& lineNames, QWidget* parent)
    : QChartView(parent), m_title(title), m_unit(unit) {
    auto* chart = new QChart();
    chart->setMargins(QMargins(2, 2, 2, 2));
    chart->legend()->setVisible(lineNames.size() > 1);
    chart->legend()->setAlignment(Qt::AlignBottom);
    // Small panels: short labels in a small font, the unit in the title instead of axis titles.
    chart->setTitle(QStringLiteral("%1 (%2)").arg(title, unit));
    QFont labelFont = chart->font();
    labelFont.setPointSizeF(7.0);
    m_axisX = new QValueAxis(chart);
    m_axisX->setLabelFormat(QStringLiteral("%.3g"));
    m_axisX->setLabelsFont(labelFont);
    m_axisX->setTickCount(5);
    m_axisY = new QValueAxis(chart);
    m_axisY->setLabelFormat(QStringLiteral("%.3g"));
    m_axisY->setLabelsFont(labelFont);
    m_axisY->setTickCount(4);
    chart->addAxis(m_axisX, Qt::AlignBottom);
    chart->addAxis(m_axisY, Qt::AlignLeft);
    for (const QString& name : lineNames) {
        auto* series = new QLineSeries(chart);
        series->setName(name);
        chart->addSeries(series);
        series->attachAxis(m_axisX);
        series->attachAxis(m_axisY);
        m_lines.push_back(series);
    }
    // QChartView made a chart of its own, which setChart() only releases: delete it.
    QChart* const defaultChart = QChartView::chart();
    setChart(chart);
    delete defaultChart;
    setRenderHint(QPainter::Antialiasing);
    setMinimumSize(220, 160);
    setToolTip(tr("%1. Right-click to export the chart as PNG or its data as CSV.").arg(title));
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
    m_maxSeconds = 1.0;
    m_maxValue = 1.0;
    m_axisX->setRange(0.0, m_maxSeconds);
    m_axisY->setRange(0.0, m_maxValue);
}

void TimeSeriesChart::growAxes(double seconds, double value) {
    // Axes only grow (by steps of a quarter) so a live chart does not jitter every sample.
    if (seconds > m_maxSeconds) {
        m_maxSeconds = seconds * 1.25;
        m_axisX->setRange(0.0, m_maxSeconds);
    }
    if (value > m_maxValue) {
        m_maxValue = value * 1.25;
        m_axisY->setRange(0.0, m_maxValue);
    }
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
