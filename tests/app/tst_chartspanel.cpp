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
    void exportsPngAndCsv();
    void exportErrorsNameTheFile();
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
    panel.setFrame(12.0, 3.0, 40.0, 77);
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

QTEST_MAIN(TestChartsPanel)
#include "tst_chartspanel.moc"
