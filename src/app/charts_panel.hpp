// ChartsPanel: the live charts dock. Samples at most 10 times a second (its own timer) what
// the builder service and the view last reported: points inserted over time against the ideal
// constant-rate line, the insertion delay, the front size, CPU milliseconds per frame (front
// evaluation and total), frames per second, and resident memory.
#pragma once

#include "build_pipeline.hpp"

#include <QElapsedTimer>
#include <QTimer>
#include <QWidget>
#include <deque>
#include <vector>

namespace omicron {

class TimeSeriesChart;

class ChartsPanel : public QWidget {
    Q_OBJECT
public:
    static constexpr int kSampleIntervalMs = 100;

    explicit ChartsPanel(QWidget* parent = nullptr);

    const std::vector<TimeSeriesChart*>& charts() const { return m_charts; }
    TimeSeriesChart* chart(const QString& title) const;

public slots:
    // A new build: clears the build charts and restarts their clock.
    void startBuild();
    void setProgress(const omicron::PipelineProgress& progress);
    void setHierarchyBytes(std::size_t bytes);
    // The view's last frame (CPU ms for the whole frame and the front, fps, front nodes).
    void setFrame(double frameMs, double frontMs, double fps, std::size_t frontNodes);

signals:
    void exportFailed(const QString& path, const QString& message);

private:
    void sample();
    double insertionDelaySeconds(double now) const;

    std::vector<TimeSeriesChart*> m_charts;
    TimeSeriesChart* m_inserted = nullptr;
    TimeSeriesChart* m_delay = nullptr;
    TimeSeriesChart* m_front = nullptr;
    TimeSeriesChart* m_cpu = nullptr;
    TimeSeriesChart* m_fpsChart = nullptr;
    TimeSeriesChart* m_memory = nullptr;

    QTimer m_timer;
    QElapsedTimer m_clock;
    PipelineProgress m_progress;
    bool m_building = false;
    std::size_t m_hierarchyBytes = 0;
    bool m_haveFrame = false;
    double m_frameMs = 0.0;
    double m_frontMs = 0.0;
    double m_lastFps = 0.0;
    std::size_t m_frontNodes = 0;
    // (seconds, points sorted) history, to tell how long ago the inserted count was sorted.
    std::deque<std::pair<double, std::uint64_t>> m_sortedHistory;
};

} // namespace omicron
