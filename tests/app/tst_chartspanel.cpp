// ChartsPanel and its TimeSeriesChart: sampling at <= 10 Hz, the ideal line, PNG/CSV export
// (with errors that name the file), axes in human units at round ticks, one time axis for all
// charts (full history or following), and the frame rate from the first frame.
#include "chart_scale.hpp"
#include "charts_panel.hpp"
#include "frame_rate_meter.hpp"
#include "time_series_chart.hpp"

#include <QComboBox>
#include <QFile>
#include <QImage>
#include <QLineSeries>
#include <QTemporaryDir>
#include <QToolTip>
#include <QtTest>

using namespace omicron;

class TestChartsPanel : public QObject {
    Q_OBJECT
private slots:
    void samplesProgressAndFrames();
    void chartsTheLeafToDrawnDelayOfTheFrames();
    void exportsPngAndCsv();
    void exportErrorsNameTheFile();
    void memoryChartDrawsTheBudgetWhenOneIsSet();
    void ticksAreRoundAndLabelledInHumanUnits_data();
    void ticksAreRoundAndLabelledInHumanUnits();
    void exactValuesForTooltips();
    void frameRateMeterCountsFromTheFirstFrame();
    void frameRateIsChartedFromTheFirstFrameLikeCpuPerFrame();
    void chartsShareOneTimeAxisFullOrFollowing();
    void chartAxesGrowToRoundLabelledEnds();
    void hoveringALineShowsTheExactValue();
};

void TestChartsPanel::samplesProgressAndFrames() {
    ChartsPanel panel;
    panel.resize(900, 400);
    panel.show();
    QCOMPARE(panel.charts().size(), std::size_t{6});
    TimeSeriesChart* inserted = panel.chart(QStringLiteral("Inserted points"));
    TimeSeriesChart* cpu = panel.chart(QStringLiteral("CPU per frame"));
    QVERIFY(inserted != nullptr && cpu != nullptr);
    panel.startBuild();
    PipelineProgress progress;
    progress.generation = 1;
    progress.phase = BuildPhase::Sorting;
    progress.pointsTotal = 1000;
    progress.pointsSorted = 400;
    progress.pointsInserted = 100;
    panel.setProgress(progress);
    FrameStats frame;
    frame.frameMs = 12.0;
    frame.frontMs = 3.0;
    frame.fps = 40.0;
    frame.frontNodes = 77;
    panel.setFrame(frame);
    QTRY_VERIFY(inserted->line(0)->count() >= 2);
    QCOMPARE(inserted->line(0)->points().last().y(), 100.0);
    QCOMPARE(inserted->line(1)->points().last().y(), 400.0);
    // The ideal line runs from the origin to the total.
    QCOMPARE(inserted->line(2)->count(), 2);
    QCOMPARE(inserted->line(2)->at(1).y(), 1000.0);
    QTRY_VERIFY(cpu->line(0)->count() >= 1);
    QCOMPARE(cpu->line(0)->points().last().y(), 12.0);
    QCOMPARE(cpu->line(1)->points().last().y(), 3.0);
    // A finished build stops the build charts.
    progress.phase = BuildPhase::Complete;
    panel.setProgress(progress);
    QTest::qWait(3 * ChartsPanel::kSampleIntervalMs);
    const int samples = inserted->line(0)->count();
    QTest::qWait(3 * ChartsPanel::kSampleIntervalMs);
    QCOMPARE(inserted->line(0)->count(), samples);
    // <= 10 Hz: the memory chart samples at the panel's own rate.
    TimeSeriesChart* memory = panel.chart(QStringLiteral("Memory"));
    const int before = memory->line(0)->count();
    QTest::qWait(1000);
    QVERIFY(memory->line(0)->count() - before <= 11);
    QVERIFY(memory->line(0)->points().last().y() > 0.0);
}

// The front insertion delay series: the frames' leaf -> drawn delays gathered between two
// samples, their median weighted by leaf counts and their maximum; the sorted -> inserted
// delay stays as its own line.
void TestChartsPanel::chartsTheLeafToDrawnDelayOfTheFrames() {
    ChartsPanel panel;
    panel.resize(900, 400);
    panel.show();
    TimeSeriesChart* delay = panel.chart(QStringLiteral("Insertion delay"));
    QVERIFY(delay != nullptr);
    QCOMPARE(delay->lineCount(), 3);
    QCOMPARE(delay->line(0)->name(), QStringLiteral("median")); // leaf -> drawn
    QCOMPARE(delay->line(2)->name(), QStringLiteral("sort wait")); // sorted -> inserted
    panel.startBuild();
    // Three frames before the next sample: 10 leaves at 40 ms (max 90), 1 at 5 ms (max 5),
    // 30 at 70 ms (max 300); one frame that drew no new leaf.
    const auto frame = [&](std::size_t leaves, double medianMs, double maxMs) {
        FrameStats stats;
        stats.leavesFirstDrawn = leaves;
        stats.leafDrawDelayMedianMs = medianMs;
        stats.leafDrawDelayMaxMs = maxMs;
        panel.setFrame(stats);
    };
    QTest::qWait(2 * ChartsPanel::kSampleIntervalMs); // a sample with no leaves: no point
    QCOMPARE(delay->line(0)->count(), 0);
    frame(10, 40.0, 90.0);
    frame(1, 5.0, 5.0);
    frame(0, 0.0, 0.0);
    frame(30, 70.0, 300.0);
    QTRY_COMPARE(delay->line(0)->count(), 1);
    QCOMPARE(delay->line(0)->at(0).y(), 70.0); // 30 of the 41 leaves are at 70 ms
    QCOMPARE(delay->line(1)->at(0).y(), 300.0);
    QTest::qWait(3 * ChartsPanel::kSampleIntervalMs);
    QCOMPARE(delay->line(0)->count(), 1); // nothing new drawn: no new point
    frame(4, 12.0, 20.0);
    QTRY_COMPARE(delay->line(1)->count(), 2);
    QCOMPARE(delay->line(0)->at(1).y(), 12.0);
    QCOMPARE(delay->line(1)->at(1).y(), 20.0); // the window's own maximum, not the build's
}

void TestChartsPanel::exportsPngAndCsv() {
    QTemporaryDir dir;
    TimeSeriesChart chart(QStringLiteral("Front size"), QStringLiteral("nodes"), ChartUnit::Count,
                          {QStringLiteral("front nodes")});
    chart.resize(400, 300);
    chart.append(0, 0.5, 10.0);
    chart.append(0, 1.0, 25.0);
    const QString png = dir.filePath(QStringLiteral("front.png"));
    const QString csv = dir.filePath(QStringLiteral("front.csv"));
    QString error;
    QVERIFY2(chart.exportPng(png, &error), qPrintable(error));
    QVERIFY2(chart.exportCsv(csv, &error), qPrintable(error));
    const QImage image(png);
    QCOMPARE(image.size(), QSize(400, 300));
    QFile file(csv);
    QVERIFY(file.open(QIODevice::ReadOnly | QIODevice::Text));
    const QStringList lines = QString::fromUtf8(file.readAll()).split('\n', Qt::SkipEmptyParts);
    QCOMPARE(lines.size(), 3);
    QCOMPARE(lines.at(0), QStringLiteral("chart,line,time_s,value"));
    QCOMPARE(lines.at(2), QStringLiteral("\"Front size\",\"front nodes\",1,25"));
}

void TestChartsPanel::exportErrorsNameTheFile() {
    TimeSeriesChart chart(QStringLiteral("Frame rate"), QStringLiteral("fps"), ChartUnit::Rate,
                          {QStringLiteral("fps")});
    const QString bad = QStringLiteral("/nonexistent-folder/chart.csv");
    QString error;
    QVERIFY(!chart.exportCsv(bad, &error));
    QVERIFY2(error.contains(bad), qPrintable(error));
    QVERIFY(!chart.exportPng(QStringLiteral("/nonexistent-folder/chart.png"), &error));
    QVERIFY2(error.contains(QStringLiteral("/nonexistent-folder/chart.png")), qPrintable(error));
}

void TestChartsPanel::memoryChartDrawsTheBudgetWhenOneIsSet() {
    ChartsPanel panel;
    TimeSeriesChart* memory = panel.chart(QStringLiteral("Memory"));
    QVERIFY(memory != nullptr);
    QCOMPARE(memory->lineCount(), 3);
    panel.startBuild();
    panel.setMemoryBudget(std::uint64_t{256} << 20);
    QTRY_VERIFY(memory->line(0)->count() >= 2);
    QCOMPARE(memory->line(2)->count(), 2);
    QCOMPARE(memory->line(2)->at(0).y(), 256.0);
    QCOMPARE(memory->line(2)->at(1).y(), 256.0);
    QCOMPARE(memory->line(2)->at(1).x(), memory->line(0)->points().last().x());
    // Automatic (half of physical memory): no line, the chart keeps its scale.
    panel.setMemoryBudget(0);
    QTRY_COMPARE(memory->line(2)->count(), 0);
}

void TestChartsPanel::ticksAreRoundAndLabelledInHumanUnits_data() {
    QTest::addColumn<double>("max");
    QTest::addColumn<int>("unit");
    QTest::addColumn<QStringList>("labels");
    const auto row = [](const char* name, double max, ChartUnit unit, QStringList labels) {
        QTest::newRow(name) << max << static_cast<int>(unit) << labels;
    };
    row("points in millions", 30.25e6, ChartUnit::Count,
        {"0", "10 M", "20 M", "30 M"});
    row("points in tenths of millions", 1.5e6, ChartUnit::Count,
        {"0", "0.5 M", "1.0 M", "1.5 M"});
    row("nodes in thousands", 6000.0 * 4, ChartUnit::Count, {"0", "10 k", "20 k"});
    row("few nodes", 12.0, ChartUnit::Count, {"0", "5", "10"});
    row("a billion points", 2.2e9, ChartUnit::Count, {"0", "1 G", "2 G"});
    row("memory in MiB", 500.0, ChartUnit::Mebibytes, {"0", "200 MiB", "400 MiB"});
    row("memory in GiB", 1.5 * 1024, ChartUnit::Mebibytes,
        {"0", "0.5 GiB", "1.0 GiB", "1.5 GiB"});
    row("frame ms", 96.8, ChartUnit::Milliseconds, {"0", "20 ms", "40 ms", "60 ms", "80 ms"});
    row("long delays in s", 6000.0, ChartUnit::Milliseconds, {"0", "2 s", "4 s", "6 s"});
    row("seconds", 9.2, ChartUnit::Seconds, {"0 s", "2 s", "4 s", "6 s", "8 s"});
    row("fps", 60.0, ChartUnit::Rate, {"0", "20", "40", "60"});
}

void TestChartsPanel::ticksAreRoundAndLabelledInHumanUnits() {
    QFETCH(double, max);
    QFETCH(int, unit);
    QFETCH(QStringList, labels);
    const AxisTicks ticks = roundTicks(0.0, max, 4, static_cast<ChartUnit>(unit));
    QCOMPARE(tickLabels(ticks), labels);
    for (const double value : ticks.values) {
        QVERIFY(value <= max);
    }
}

void TestChartsPanel::exactValuesForTooltips() {
    QCOMPARE(exactValue(24213457.0, ChartUnit::Count), QLocale().toString(24213457));
    QCOMPARE(exactValue(12.456, ChartUnit::Milliseconds), QLocale().toString(12.46, 'f', 2));
    QCOMPARE(exactValue(1423.46, ChartUnit::Mebibytes), QLocale().toString(1423.5, 'f', 1));
}

void TestChartsPanel::frameRateMeterCountsFromTheFirstFrame() {
    FrameRateMeter meter;
    QCOMPARE(meter.rateAt(5.0), 0.0);
    // 60 frames a second from t = 10 s: the first sample 0.1 s in already has the rate.
    for (int i = 0; i < 6; ++i) {
        meter.frameAt(10.0 + i / 60.0);
    }
    QCOMPARE(meter.rateAt(10.1), 60.0);
    for (int i = 6; i < 120; ++i) {
        meter.frameAt(10.0 + i / 60.0);
    }
    QVERIFY(std::abs(meter.rateAt(12.0 - 1e-9) - 60.0) < 1.01);
    // Frames stop: the rate falls to 0 once the last frame is a second old.
    QVERIFY(meter.rateAt(12.5) > 0.0);
    QCOMPARE(meter.rateAt(13.1), 0.0);
    // After the pause, 3 frames in 0.2 s are 15 fps, not diluted by the idle second.
    meter.frameAt(20.0);
    meter.frameAt(20.1);
    meter.frameAt(20.2);
    QCOMPARE(meter.rateAt(20.2), 15.0);
}

// The frame rate chart gets its first sample with the first frame, as CPU per frame does.
void TestChartsPanel::frameRateIsChartedFromTheFirstFrameLikeCpuPerFrame() {
    ChartsPanel panel;
    panel.resize(900, 400);
    panel.show();
    panel.startBuild();
    TimeSeriesChart* cpu = panel.chart(QStringLiteral("CPU per frame"));
    TimeSeriesChart* fps = panel.chart(QStringLiteral("Frame rate"));
    QTest::qWait(2 * ChartsPanel::kSampleIntervalMs);
    QCOMPARE(cpu->line(0)->count(), 0);
    QCOMPARE(fps->line(0)->count(), 0);
    FrameStats frame;
    frame.frameMs = 8.0;
    frame.fps = 0.0; // the view's own one-second figure is not there yet
    for (int i = 0; i < 4; ++i) {
        panel.setFrame(frame);
        QTest::qWait(10);
    }
    QTRY_VERIFY(cpu->line(0)->count() >= 1);
    QCOMPARE(fps->line(0)->count(), cpu->line(0)->count());
    QCOMPARE(fps->line(0)->at(0).x(), cpu->line(0)->at(0).x());
    QVERIFY2(fps->line(0)->at(0).y() >= 4.0, qPrintable(QString::number(fps->line(0)->at(0).y())));
    QCOMPARE(cpu->line(0)->at(0).y(), 8.0);
}

void TestChartsPanel::chartsShareOneTimeAxisFullOrFollowing() {
    ChartsPanel panel;
    panel.resize(900, 400);
    panel.show();
    panel.startBuild();
    const auto sameAxis = [&] {
        for (const TimeSeriesChart* chart : panel.charts()) {
            if (chart->timeFrom() != panel.charts().front()->timeFrom() ||
                chart->timeTo() != panel.charts().front()->timeTo()) {
                return false;
            }
        }
        return true;
    };
    QTest::qWait(5 * ChartsPanel::kSampleIntervalMs);
    QVERIFY(sameAxis());
    QCOMPARE(panel.charts().front()->timeFrom(), 0.0);
    // Full history: from the open to past the last sample.
    const TimeSeriesChart* memory = panel.chart(QStringLiteral("Memory"));
    QVERIFY(memory->line(0)->count() > 0);
    QVERIFY(panel.charts().front()->timeTo() >= memory->line(0)->points().last().x());
    // Following the last 10 s: a 10 s window on every chart, whichever its samples.
    panel.setFollowSeconds(10.0);
    QVERIFY(sameAxis());
    QCOMPARE(panel.charts().front()->timeTo() - panel.charts().front()->timeFrom(), 10.0);
    auto* combo = panel.findChild<QComboBox*>(QStringLiteral("timeWindow"));
    QVERIFY(combo != nullptr);
    QCOMPARE(combo->currentData().toDouble(), 10.0);
    combo->setCurrentIndex(0);
    QCOMPARE(panel.followSeconds(), 0.0);
    QVERIFY(sameAxis());
    QCOMPARE(panel.charts().front()->timeFrom(), 0.0);
}

void TestChartsPanel::chartAxesGrowToRoundLabelledEnds() {
    TimeSeriesChart chart(QStringLiteral("Inserted points"), QStringLiteral("points"),
                          ChartUnit::Count, {QStringLiteral("inserted")});
    chart.resize(300, 200);
    chart.append(0, 0.4, 2.42e7);
    chart.append(0, 7.3, 8.07e6);
    const QStringList labels = chart.axisLabels();
    QVERIFY(labels.contains(QStringLiteral("0 s")));
    QVERIFY2(labels.contains(QStringLiteral("20 M")), qPrintable(labels.join(", ")));
    for (const QString& label : labels) {
        QVERIFY2(!label.contains(QLatin1Char('e')), qPrintable(label));
    }
}

void TestChartsPanel::hoveringALineShowsTheExactValue() {
    TimeSeriesChart chart(QStringLiteral("Inserted points"), QStringLiteral("points"),
                          ChartUnit::Count, {QStringLiteral("inserted")});
    chart.resize(300, 200);
    chart.show();
    QVERIFY(QTest::qWaitForWindowExposed(&chart));
    chart.append(0, 1.0, 1000.0);
    chart.append(0, 2.0, 24213457.0);
    // Qt reports a point on the line between samples: the tooltip names the nearest sample.
    emit chart.line(0)->hovered(QPointF(1.9, 23e6), true);
    QTRY_VERIFY(QToolTip::isVisible());
    QCOMPARE(QToolTip::text(), QStringLiteral("inserted at %1 s: %2 points")
                                   .arg(QLocale().toString(2.0, 'f', 2),
                                        QLocale().toString(24213457)));
    emit chart.line(0)->hovered(QPointF(1.9, 23e6), false);
    QTRY_VERIFY(!QToolTip::isVisible());
}

QTEST_MAIN(TestChartsPanel)
#include "tst_chartspanel.moc"
