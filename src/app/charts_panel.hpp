// ChartsPanel: the live charts dock. Samples at most 10 times a second (its own timer) what
// the builder service and the view last reported: points inserted over time against the ideal
// constant-rate line, the insertion delays (the paper's front insertion delay, leaf published
// -> first drawn, from the view's frames; and sorted -> inserted, from the build's progress),
// the front size, CPU milliseconds per frame (front evaluation and total), frames per second,
// and resident memory against the memory budget. All charts share one time axis, seconds
// since the open: the whole history, or a window following the last seconds.
#pragma once

#include "frame_rate_meter.hpp"
#include "pipeline/build_pipeline.hpp"
#include "render_settings.hpp"

#include <QElapsedTimer>
#include <QTimer>
#include <QWidget>
#include <deque>
#include <vector>

class QComboBox;

namespace omicron {

class TimeSeriesChart;

class ChartsPanel : public QWidget {
    Q_OBJECT
public:
    static constexpr int kSampleIntervalMs = 100;

    explicit ChartsPanel(QWidget* parent = nullptr);

    const std::vector<TimeSeriesChart*>& charts() const { return m_charts; }
    TimeSeriesChart* chart(const QString& title) const;

    // The time axis of every chart: 0 shows the whole history, N > 0 follows the last N s
    // (the panel's menu offers 10 s, 30 s, 1 min and 5 min; the window persists the choice).
    void setFollowSeconds(double seconds);
    double followSeconds() const { return m_followSeconds; }
    // Frames per second now, as the Frame rate chart draws it (FrameRateMeter).
    double frameRate();

public slots:
    // A new build: clears the build charts and restarts their clock.
    void startBuild();
    void setProgress(const omicron::PipelineProgress& progress);
    void setHierarchyBytes(std::size_t bytes);
    // The memory budget the build was started with, drawn as a line on the memory chart;
    // 0 (automatic: half of physical memory) draws none, so the chart keeps its detail.
    void setMemoryBudget(std::uint64_t bytes);
    // A frame of the view: CPU ms for the whole frame and the front, fps, front nodes, and
    // the leaves it drew first (their delays are gathered until the next sample).
    void setFrame(const omicron::FrameStats& stats);

signals:
    void exportFailed(const QString& path, const QString& message);

private:
    void sample();
    void setSharedTimeRange(double now);
    double insertionDelaySeconds(double now) const;
    // Median (over the frames' medians, weighted by their leaf counts) and maximum of the
    // leaf -> drawn delays of the frames since the last sample; false when none drew a leaf.
    bool takeLeafDelays(double& medianMs, double& maxMs);

    std::vector<TimeSeriesChart*> m_charts;
    TimeSeriesChart* m_inserted = nullptr;
    TimeSeriesChart* m_delay = nullptr;
    TimeSeriesChart* m_front = nullptr;
    TimeSeriesChart* m_cpu = nullptr;
    TimeSeriesChart* m_fpsChart = nullptr;
    TimeSeriesChart* m_memory = nullptr;

    QComboBox* m_timeWindow = nullptr;
    double m_followSeconds = 0.0;
    double m_historyEnd = 1.0; // the full-history axis only grows, in round steps
    FrameRateMeter m_frameRate;

    QTimer m_timer;
    QElapsedTimer m_clock;
    PipelineProgress m_progress;
    bool m_building = false;
    std::size_t m_hierarchyBytes = 0;
    std::uint64_t m_memoryBudgetBytes = 0;
    bool m_haveFrame = false;
    double m_frameMs = 0.0;
    double m_frontMs = 0.0;
    std::size_t m_frontNodes = 0;
    // (frame median ms, leaves first drawn) of the frames since the last sample, and their max.
    std::vector<std::pair<double, std::size_t>> m_leafDelayMedians;
    double m_leafDelayMaxMs = 0.0;
    // (seconds, points sorted) history, to tell how long ago the inserted count was sorted.
    std::deque<std::pair<double, std::uint64_t>> m_sortedHistory;
};

} // namespace omicron
