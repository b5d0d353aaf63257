#include "charts_panel.hpp"

#include "memory_budget.hpp"
#include "time_series_chart.hpp"

#include <QComboBox>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineSeries>
#include <QVBoxLayout>
#include <algorithm>

namespace omicron {

ChartsPanel::ChartsPanel(QWidget* parent) : QWidget(parent) {
    auto* column = new QVBoxLayout(this);
    column->setContentsMargins(2, 2, 2, 2);
    column->setSpacing(2);
    auto* controls = new QHBoxLayout();
    controls->addWidget(new QLabel(tr("Time axis:"), this));
    m_timeWindow = new QComboBox(this);
    m_timeWindow->setObjectName(QStringLiteral("timeWindow"));
    m_timeWindow->setToolTip(tr("All charts share this time axis (seconds since the open): "
                                "the whole history, or a window that follows the last seconds"));
    m_timeWindow->addItem(tr("Full history"), 0.0);
    for (const int seconds : {10, 30, 60, 300}) {
        m_timeWindow->addItem(seconds < 60 ? tr("Follow last %1 s").arg(seconds)
                                           : tr("Follow last %1 min").arg(seconds / 60),
                              static_cast<double>(seconds));
    }
    connect(m_timeWindow, &QComboBox::currentIndexChanged, this, [this](int index) {
        setFollowSeconds(m_timeWindow->itemData(index).toDouble());
    });
    controls->addWidget(m_timeWindow);
    controls->addStretch(1);
    column->addLayout(controls);
    auto* grid = new QGridLayout();
    grid->setSpacing(2);
    column->addLayout(grid, 1);
    const auto add = [&](const QString& title, const QString& unit, ChartUnit scale,
                         const QStringList& lines) {
        auto* chart = new TimeSeriesChart(title, unit, scale, lines, this);
        connect(chart, &TimeSeriesChart::exportFailed, this, &ChartsPanel::exportFailed);
        const int index = static_cast<int>(m_charts.size());
        grid->addWidget(chart, index / 3, index % 3);
        m_charts.push_back(chart);
        return chart;
    };
    // Line names stay short so legends fit a small panel; the tooltips say what they mean.
    m_inserted = add(tr("Inserted points"), tr("points"), ChartUnit::Count,
                     {tr("inserted"), tr("sorted"), tr("ideal")});
    m_delay = add(tr("Insertion delay"), tr("ms"), ChartUnit::Milliseconds,
                  {tr("median"), tr("max"), tr("sort wait")});
    // Leaves are first drawn in bursts while a build runs: mark every sample, a lone one too.
    for (int line = 0; line < m_delay->lineCount(); ++line) {
        m_delay->line(line)->setPointsVisible(true);
    }
    m_front = add(tr("Front size"), tr("nodes"), ChartUnit::Count, {tr("front nodes")});
    m_cpu = add(tr("CPU per frame"), tr("ms"), ChartUnit::Milliseconds,
                {tr("total"), tr("front")});
    m_fpsChart = add(tr("Frame rate"), tr("fps"), ChartUnit::Rate, {tr("fps")});
    m_memory = add(tr("Memory"), tr("MiB"), ChartUnit::Mebibytes,
                   {tr("resident"), tr("hierarchy"), tr("budget")});
    m_inserted->setToolTip(m_inserted->toolTip() +
                           tr("\ninserted: points inserted into the hierarchy.\nsorted: points "
                              "the sorter has handed on.\nideal: the straight line to the final "
                              "point count, insertion at a constant rate."));
    m_delay->setToolTip(
        m_delay->toolTip() +
        tr("\nmedian / max: leaf published -> drawn, the paper's front insertion "
           "delay, from the builder publishing a leaf to the first frame of the view that draws "
           "its points (its own node, or an ancestor standing for it); median and maximum over "
           "the leaves first drawn since the previous sample.\nsort wait: sorted -> inserted, "
           "how long ago the points now inserted into the hierarchy had been sorted, the wait "
           "between the sorter and the builder."));
    m_cpu->setToolTip(m_cpu->toolTip() +
                      tr("\ntotal: CPU time of the whole frame.\nfront: of which evaluating "
                         "the render front."));
    m_fpsChart->setToolTip(m_fpsChart->toolTip() +
                           tr("\nFrames drawn in the last second, from the first frame on "
                              "(the view draws on demand: 0 while nothing changes)."));
    m_memory->setToolTip(m_memory->toolTip() +
                         tr("\nresident: the process's resident memory.\nhierarchy: the "
                            "hierarchy and the sorted cloud.\nbudget: the memory budget the "
                            "build runs under, when one is set."));
    m_timer.setInterval(kSampleIntervalMs);
    connect(&m_timer, &QTimer::timeout, this, &ChartsPanel::sample);
    m_clock.start();
    m_timer.start();
    setSharedTimeRange(0.0);
}

void ChartsPanel::setFollowSeconds(double seconds) {
    m_followSeconds = std::max(0.0, seconds);
    const int index = m_timeWindow->findData(m_followSeconds);
    if (index >= 0 && index != m_timeWindow->currentIndex()) {
        m_timeWindow->setCurrentIndex(index);
    }
    setSharedTimeRange(m_clock.nsecsElapsed() * 1e-9);
}

double ChartsPanel::frameRate() {
    return m_frameRate.rateAt(m_clock.nsecsElapsed() * 1e-9);
}

void ChartsPanel::setSharedTimeRange(double now) {
    double from = 0.0, to = 0.0;
    if (m_followSeconds > 0.0) {
        to = std::max(now, m_followSeconds);
        from = to - m_followSeconds;
    } else {
        if (now > m_historyEnd) {
            m_historyEnd = roundAxisEnd(now * 1.2, 6, ChartUnit::Seconds);
        }
        to = m_historyEnd;
    }
    for (TimeSeriesChart* chart : m_charts) {
        chart->setTimeRange(from, to);
    }
}

TimeSeriesChart* ChartsPanel::chart(const QString& title) const {
    for (TimeSeriesChart* chart : m_charts) {
        if (chart->title() == title) {
            return chart;
        }
    }
    return nullptr;
}

void ChartsPanel::startBuild() {
    for (TimeSeriesChart* chart : m_charts) {
        chart->clear();
    }
    m_clock.restart();
    m_historyEnd = 1.0;
    m_frameRate.reset();
    m_haveFrame = false;
    setSharedTimeRange(0.0);
    m_progress = {};
    m_sortedHistory.clear();
    m_leafDelayMedians.clear();
    m_leafDelayMaxMs = 0.0;
    m_building = true;
}

void ChartsPanel::setProgress(const PipelineProgress& progress) {
    m_progress = progress;
}

void ChartsPanel::setHierarchyBytes(std::size_t bytes) {
    m_hierarchyBytes = bytes;
}

void ChartsPanel::setMemoryBudget(std::uint64_t bytes) {
    m_memoryBudgetBytes = bytes;
}

void ChartsPanel::setFrame(const FrameStats& stats) {
    m_haveFrame = true;
    m_frameRate.frameAt(m_clock.nsecsElapsed() * 1e-9);
    m_frameMs = stats.frameMs;
    m_frontMs = stats.frontMs;
    m_frontNodes = stats.frontNodes;
    if (stats.leavesFirstDrawn > 0) {
        m_leafDelayMedians.emplace_back(stats.leafDrawDelayMedianMs, stats.leavesFirstDrawn);
        m_leafDelayMaxMs = std::max(m_leafDelayMaxMs, stats.leafDrawDelayMaxMs);
    }
}

bool ChartsPanel::takeLeafDelays(double& medianMs, double& maxMs) {
    if (m_leafDelayMedians.empty()) {
        return false;
    }
    std::sort(m_leafDelayMedians.begin(), m_leafDelayMedians.end());
    std::size_t total = 0;
    for (const auto& [median, leaves] : m_leafDelayMedians) {
        total += leaves;
    }
    std::size_t seen = 0;
    for (const auto& [median, leaves] : m_leafDelayMedians) {
        seen += leaves;
        if (2 * seen >= total) {
            medianMs = median;
            break;
        }
    }
    maxMs = m_leafDelayMaxMs;
    m_leafDelayMedians.clear();
    m_leafDelayMaxMs = 0.0;
    return true;
}

double ChartsPanel::insertionDelaySeconds(double now) const {
    for (const auto& [seconds, sorted] : m_sortedHistory) {
        if (sorted >= m_progress.pointsInserted) {
            return now - seconds;
        }
    }
    return 0.0;
}

void ChartsPanel::sample() {
    const double now = m_clock.nsecsElapsed() * 1e-9;
    setSharedTimeRange(now);
    if (m_building) {
        m_inserted->append(0, now, static_cast<double>(m_progress.pointsInserted));
        m_inserted->append(1, now, static_cast<double>(m_progress.pointsSorted));
        if (m_progress.pointsTotal > 0) {
            m_inserted->setLine(
                2, {QPointF(0.0, 0.0), QPointF(now, static_cast<double>(m_progress.pointsTotal))});
        }
        if (m_progress.pointsSorted > 0) {
            m_sortedHistory.emplace_back(now, m_progress.pointsSorted);
            if (m_progress.pointsInserted > 0) {
                m_delay->append(2, now, 1000.0 * insertionDelaySeconds(now));
            }
        }
        const bool ended = m_progress.phase == BuildPhase::Complete ||
                           m_progress.phase == BuildPhase::Cancelled ||
                           m_progress.phase == BuildPhase::Failed;
        if (ended && m_progress.generation != 0) {
            m_building = false; // the build charts keep their last state
        }
    }
    double medianMs = 0.0, maxMs = 0.0;
    if (takeLeafDelays(medianMs, maxMs)) {
        m_delay->append(0, now, medianMs);
        m_delay->append(1, now, maxMs);
    }
    if (m_haveFrame) {
        m_front->append(0, now, static_cast<double>(m_frontNodes));
        m_cpu->append(0, now, m_frameMs);
        m_cpu->append(1, now, m_frontMs);
        m_fpsChart->append(0, now, m_frameRate.rateAt(now));
    }
    m_memory->append(0, now, static_cast<double>(processResidentSet().bytes) / 1048576.0);
    m_memory->append(1, now, static_cast<double>(m_hierarchyBytes) / 1048576.0);
    if (m_memoryBudgetBytes > 0) {
        m_memory->setLine(2, {QPointF(0.0, static_cast<double>(m_memoryBudgetBytes) / 1048576.0),
                              QPointF(now, static_cast<double>(m_memoryBudgetBytes) / 1048576.0)});
    } else if (m_memory->line(2)->count() > 0) {
        m_memory->setLine(2, {});
    }
}

} // namespace omicron
