// MainWindow read at a glance (GL: it hosts CloudView): after a real build at common screen
// sizes, no chart text is in exponent notation or cut short, every chart shows the same time
// range, and the level table shows all its columns; a first start fills most of the screen.
// With OMICRON_SCREENSHOT_DIR set, each size's window is saved there as a PNG (the README's
// screenshot comes from it).
#include "app_test_support.hpp"
#include "builder_service.hpp"
#include "charts_panel.hpp"
#include "cut_panel.hpp"
#include "main_window.hpp"
#include "time_series_chart.hpp"

#include <QDir>
#include <QGraphicsScene>
#include <QGraphicsSimpleTextItem>
#include <QGraphicsTextItem>
#include <QGuiApplication>
#include <QHeaderView>
#include <QLineSeries>
#include <QRegularExpression>
#include <QScreen>
#include <QScrollBar>
#include <QSettings>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QTableView>
#include <QtTest>

using namespace omicron;

namespace {

constexpr int kBuildTimeoutMs = 120'000;

// The text a chart draws: title, axis labels, legend entries.
QStringList drawnTexts(const TimeSeriesChart& chart) {
    QStringList texts;
    for (const QGraphicsItem* item : chart.scene()->items()) {
        if (const auto* text = dynamic_cast<const QGraphicsTextItem*>(item)) {
            if (text->isVisible()) {
                texts.append(text->toPlainText());
            }
        } else if (const auto* simple = dynamic_cast<const QGraphicsSimpleTextItem*>(item)) {
            if (simple->isVisible()) {
                texts.append(simple->text());
            }
        }
    }
    return texts;
}

} // namespace

class TestMainWindowLayoutGL : public QObject {
    Q_OBJECT
private slots:
    void initTestCase();
    void firstStartFillsMostOfTheScreen();
    void panelsReadAtAGlanceAfterABuild_data();
    void panelsReadAtAGlanceAfterABuild();
};

void TestMainWindowLayoutGL::initTestCase() {
    QStandardPaths::setTestModeEnabled(true);
    QCoreApplication::setOrganizationName(QStringLiteral("omicron-tests"));
    QCoreApplication::setApplicationName(QStringLiteral("tst_mainwindowlayoutGL"));
    QSettings().clear();
}

void TestMainWindowLayoutGL::firstStartFillsMostOfTheScreen() {
    QSettings().clear();
    MainWindow window;
    const QRect screen = QGuiApplication::primaryScreen()->availableGeometry();
    QCOMPARE(window.width(), screen.width() * 9 / 10);
    QCOMPARE(window.height(), screen.height() * 9 / 10);
}

void TestMainWindowLayoutGL::panelsReadAtAGlanceAfterABuild_data() {
    QTest::addColumn<QSize>("size");
    QTest::newRow("1280x800") << QSize(1280, 800);
    QTest::newRow("1920x1080") << QSize(1920, 1080);
}

void TestMainWindowLayoutGL::panelsReadAtAGlanceAfterABuild() {
    QFETCH(QSize, size);
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_south.ply");
    QSettings().clear();
    MainWindow window;
    window.resize(size);
    window.applyDefaultDockSizes(size);
    window.show();
    QVERIFY(QTest::qWaitForWindowExposed(&window));
    // The panels' minimum sizes fit the window: it stays the size asked for.
    QVERIFY2(window.width() <= size.width() && window.height() <= size.height(),
             qPrintable(QStringLiteral("%1x%2").arg(window.width()).arg(window.height())));
    QSignalSpy finished(window.service(), &BuilderService::buildFinished);
    window.openFile(path);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!window.service()->busy());
    // Samples of every kind on the charts: the build's, the frames' and the memory's.
    const ChartsPanel* charts = window.chartsPanel();
    TimeSeriesChart* inserted = charts->chart(QStringLiteral("Inserted points"));
    TimeSeriesChart* fps = charts->chart(QStringLiteral("Frame rate"));
    QTRY_VERIFY(inserted->line(0)->count() >= 1 && fps->line(0)->count() >= 1);
    QTest::qWait(3 * ChartsPanel::kSampleIntervalMs);
    QVERIFY(inserted->line(0)->points().last().y() > 1e6); // labels in millions were needed

    const QString screenshots = qEnvironmentVariable("OMICRON_SCREENSHOT_DIR");
    if (!screenshots.isEmpty()) {
        const QString file = QDir(screenshots).filePath(
            QStringLiteral("omicron-app-%1x%2.png").arg(size.width()).arg(size.height()));
        QVERIFY2(window.grab().save(file), qPrintable(file));
    }

    const QRegularExpression exponent(QStringLiteral("\\d[eE][+-]?\\d"));
    for (const TimeSeriesChart* chart : charts->charts()) {
        // Whole in the dock: not scrolled out of its scroll area's viewport.
        const QWidget* viewport = charts->parentWidget();
        const QRect shown(chart->mapTo(viewport, QPoint(0, 0)), chart->size());
        QVERIFY2(viewport->rect().contains(shown),
                 qPrintable(chart->title() + QStringLiteral(" at %1,%2 %3x%4 in a %5x%6 dock")
                                                 .arg(shown.x())
                                                 .arg(shown.y())
                                                 .arg(shown.width())
                                                 .arg(shown.height())
                                                 .arg(viewport->width())
                                                 .arg(viewport->height())));
        QCOMPARE(chart->timeFrom(), charts->charts().front()->timeFrom());
        QCOMPARE(chart->timeTo(), charts->charts().front()->timeTo());
        for (const QString& label : chart->axisLabels()) {
            QVERIFY2(!exponent.match(label).hasMatch(),
                     qPrintable(chart->title() + QStringLiteral(": ") + label));
        }
        // What the chart draws, once a layout pass has followed the last sample (labels are
        // laid out again when ticks change, in the event loop before the next paint).
        const auto firstUnreadable = [&]() -> QString {
            const QStringList texts = drawnTexts(*chart);
            const QString all = chart->title() + QStringLiteral(" (plot %1x%2, labels %3): ")
                                                     .arg(chart->chart()->plotArea().width())
                                                     .arg(chart->chart()->plotArea().height())
                                                     .arg(chart->axisLabels().join(QStringLiteral(","))) +
                                texts.join(QStringLiteral(" | "));
            if (!texts.contains(chart->title())) {
                return QStringLiteral("no title in ") + all;
            }
            for (int line = 0; chart->lineCount() > 1 && line < chart->lineCount(); ++line) {
                if (!texts.contains(chart->line(line)->name())) { // a single line has no legend
                    return QStringLiteral("legend misses ") + chart->line(line)->name() +
                           QStringLiteral(" in ") + all;
                }
            }
            for (const QString& text : texts) {
                if (exponent.match(text).hasMatch()) {
                    return QStringLiteral("exponent in ") + all;
                }
                if (text.endsWith(QStringLiteral("...")) || text.endsWith(QChar(0x2026))) {
                    return QStringLiteral("cut short: ") + text + QStringLiteral(" in ") + all;
                }
            }
            return {};
        };
        QTRY_COMPARE(firstUnreadable(), QString());
    }

    // Every column of the level table within its viewport, with no scrolling.
    QTableView* table = window.cutPanel()->levelTable();
    QHeaderView* header = table->horizontalHeader();
    for (int column = 0; column < header->count(); ++column) {
        QVERIFY2(header->sectionViewportPosition(column) >= 0 &&
                     header->sectionViewportPosition(column) + header->sectionSize(column) <=
                         table->viewport()->width(),
                 qPrintable(QStringLiteral("column %1 (%2) ends at %3 of %4")
                                .arg(column)
                                .arg(table->model()->headerData(column, Qt::Horizontal).toString())
                                .arg(header->sectionViewportPosition(column) +
                                     header->sectionSize(column))
                                .arg(table->viewport()->width())));
    }
    QVERIFY(!table->horizontalScrollBar()->isVisible());

}

QTEST_MAIN(TestMainWindowLayoutGL)
#include "tst_mainwindowlayoutGL.moc"
