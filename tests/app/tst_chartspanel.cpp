// ChartsPanel and its TimeSeriesChart: sampling at <= 10 Hz, the ideal line, and PNG/CSV
// export (with errors that name the file).
#include "charts_panel.hpp"
#include "time_series_chart.hpp"

#include <QFile>
#include <QImage>
#include <QLineSeries>
#include <QTemporaryDir>
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
    QVERIFY(delay->line(0)->name().contains(QStringLiteral("drawn")));
    QVERIFY(delay->line(2)->name().contains(QStringLiteral("sorted -> inserted")));
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
    TimeSeriesChart chart(QStringLiteral("Front size"), QStringLiteral("nodes"),
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
    TimeSeriesChart chart(QStringLiteral("Frame rate"), QStringLiteral("fps"),
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

QTEST_MAIN(TestChartsPanel)
#include "tst_chartspanel.moc"
