#include "charts_panel.hpp"

#include "memory_budget.hpp"
#include "time_series_chart.hpp"

#include <QGridLayout>
#include <QLineSeries>
#include <algorithm>

namespace omicron {

ChartsPanel::ChartsPanel(QWidget* parent) : QWidget(parent) {
    auto* grid = new QGridLayout(this);
    grid->setContentsMargins(2, 2, 2, 2);
    grid->setSpacing(2);
    const auto add = [&](const QString& title, const QString& unit, const QStringList& lines) {
        auto* chart = new TimeSeriesChart(title, unit, lines, this);
        connect(chart, &TimeSeriesChart::exportFailed, this, &ChartsPanel::exportFailed);
        const int index = static_cast<int>(m_charts.size());
        grid->addWidget(chart, index / 3, index % 3);
        m_charts.push_back(chart);
        return chart;
    };
    m_inserted = add(tr("Inserted points"), tr("points"),
                     {tr("inserted"), tr("sorted"), tr("ideal (constant rate)")});
    m_delay = add(tr("Insertion delay"), tr("ms"),
                  {tr("leaf -> drawn median"), tr("leaf -> drawn max"), tr("sorted -> inserted")});
    // Leaves are first drawn in bursts while a build runs: mark every sample, a lone one too.
    for (int line = 0; line < m_delay->lineCount(); ++line) {
        m_delay->line(line)->setPointsVisible(true);
    }
    m_front = add(tr("Front size"), tr("nodes"), {tr("front nodes")});
    m_cpu = add(tr("CPU per frame"), tr("ms"), {tr("total"), tr("front evaluation")});
    m_fpsChart = add(tr("Frame rate"), tr("fps"), {tr("fps")});
    m_memory = add(tr("Memory"), tr("MiB"),
                   {tr("process resident"), tr("hierarchy + cloud"), tr("budget")});
    m_inserted->setToolTip(m_inserted->toolTip() +
                           tr("\nThe ideal line is the straight line to the final point count: "
                              "insertion at a constant rate."));
    m_delay->setToolTip(
        m_delay->toolTip() +
        tr("\nLeaf published -> drawn: the paper's front insertion delay, from the builder "
           "publishing a leaf to the first frame of the view that draws its points (its own "
           "node, or an ancestor standing for it); median and maximum over the leaves first "
           "drawn since the previous sample.\nSorted -> inserted: how long ago the points now "
           "inserted into the hierarchy had been sorted, the wait between the sorter and the "
           "builder."));
    m_timer.setInterval(kSampleIntervalMs);
    connect(&m_timer, &QTimer::timeout, this, &ChartsPanel::sample);
    m_clock.start();
    m_timer.start();
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
    m_frameMs = stats.frameMs;
    m_frontMs = stats.frontMs;
    m_lastFps = stats.fps;
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
        m_fpsChart->append(0, now, m_lastFps);
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
