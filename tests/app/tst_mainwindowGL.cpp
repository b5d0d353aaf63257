// MainWindow end to end (GL: it hosts CloudView): open a shared file through the menu's entry
// and wait for the build, panels and status follow, the level model passes the model tester,
// a malformed file shows a named error and the app stays usable, settings persist, closing
// mid-build returns promptly.
#include "app_test_support.hpp"
#include "build_panel.hpp"
#include "builder_service.hpp"
#include "charts_panel.hpp"
#include "cloud_view.hpp"
#include "cut_panel.hpp"
#include "hierarchy_model.hpp"
#include "level_model.hpp"
#include "main_window.hpp"
#include "measurements_panel.hpp"
#include "memory_budget.hpp"
#include "time_series_chart.hpp"
#include "widget_test_support.hpp"

#include <QAbstractItemModelTester>
#include <QAction>
#include <QComboBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QLineSeries>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QSettings>
#include <QSignalSpy>
#include <QPushButton>
#include <QSpinBox>
#include <QTableWidget>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTreeView>
#include <QtTest>

using namespace omicron;

namespace {
constexpr int kBuildTimeoutMs = 120'000;

// The level table's "Front nodes" column against the view's last frame: the same numbers,
// adding up to the front's size.
bool frontColumnMatchesTheView(const MainWindow& window) {
    const FrameStats stats = window.cloudView()->lastFrameStats();
    const LevelModel* levels = window.cutPanel()->levelModel();
    std::size_t sum = 0, perLevel = 0;
    for (int level = 0; level < levels->rowCount(); ++level) {
        const quint64 shown = levels->value(level, LevelModel::FrontNodes);
        if (shown != stats.frontNodesPerLevel[static_cast<std::size_t>(level)]) {
            return false;
        }
        sum += shown;
    }
    for (const std::size_t count : stats.frontNodesPerLevel) {
        perLevel += count;
    }
    return stats.frontNodes > 0 && sum == stats.frontNodes && perLevel == stats.frontNodes;
}
} // namespace

class TestMainWindowGL : public QObject {
    Q_OBJECT
private slots:
    void initTestCase();
    void openingASharedFileBuildsAndFillsThePanels();
    void malformedFileShowsANamedErrorAndTheAppStaysUsable();
    void savedHierarchyOpensThroughTheFileMenu();
    void potreeExportThroughTheFileMenu();
    void closingMidBuildReturnsPromptly();
    void aCloudBeyondTheMemoryBudgetSortsOnDisk();
    void renderModeMenuAndPanelDriveTheView();
    void hierarchyTreeSelectionHighlightsTheNodeInTheView();
};

void TestMainWindowGL::initTestCase() {
    // Keep the user's settings out of the tests (QSettings follows the test-mode paths).
    QStandardPaths::setTestModeEnabled(true);
    QCoreApplication::setOrganizationName(QStringLiteral("omicron-tests"));
    QCoreApplication::setApplicationName(QStringLiteral("tst_mainwindowGL"));
    QSettings().clear();
}

void TestMainWindowGL::openingASharedFileBuildsAndFillsThePanels() {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    QTemporaryDir dir;
    {
        MainWindow window;
        window.resize(1400, 900);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        QAbstractItemModelTester tester(window.cutPanel()->levelModel(),
                                        QAbstractItemModelTester::FailureReportingMode::QtTest);
        QAbstractItemModelTester treeTester(window.cutPanel()->hierarchyModel(),
                                            QAbstractItemModelTester::FailureReportingMode::QtTest);
        QSignalSpy finished(window.service(), &BuilderService::buildFinished);
        window.openFile(path);
        QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
        QTRY_VERIFY(!window.service()->busy());
        const auto result = finished.first().at(0).value<PipelineResult>();
        QVERIFY(result.stats.complete);
        QVERIFY(window.windowTitle().contains(QStringLiteral("bunny.ply")));
        // Panels show the finished build.
        for (int bar = 0; bar < 4; ++bar) {
            QCOMPARE(window.cutPanel()->barValue(bar), 1000);
        }
        LevelModel* levels = window.cutPanel()->levelModel();
        QCOMPARE(levels->rowCount(), window.buildPanel()->pipelineOptions().build.maxLevel + 1);
        QCOMPARE(levels->value(0, LevelModel::CutRoots), quint64(1));
        QCOMPARE(levels->value(0, LevelModel::Nodes), quint64(1));
        QCOMPARE(window.recentFiles().value(0), path);
        // The view's frames fill the "Front nodes" column; the tree holds the finished root.
        QTRY_VERIFY_WITH_TIMEOUT(frontColumnMatchesTheView(window), kBuildTimeoutMs);
        QCOMPARE(window.cutPanel()->hierarchyModel()->rowCount(), 1);
        QCOMPARE(window.cutPanel()->hierarchyModel()->hierarchy(), window.service()->hierarchy());
        // Hovering a drawn point names it in the status bar; leaving the view clears it.
        auto* pickLabel = window.findChild<QLabel*>(QStringLiteral("pickLabel"));
        QVERIFY(pickLabel != nullptr);
        CloudView* view = window.cloudView();
        // A pixel the current frame draws (the front still refines between frames, so look
        // again before each try), the pointer moved there, and the label after the rest delay.
        const auto drawnPixel = [&] {
            // A coarse grid: each look reads depth back from the GPU (slow on a busy CI).
            for (int y = view->height() / 4; y < view->height() * 3 / 4; y += 16) {
                for (int x = view->width() / 4; x < view->width() * 3 / 4; x += 16) {
                    if (view->pickCloudPoint(QPoint(x, y))) {
                        return QPoint(x, y);
                    }
                }
            }
            return QPoint(-1, -1);
        };
        const auto hoverNamesAPoint = [&] {
            const QPoint onCloud = drawnPixel();
            if (onCloud.x() < 0) {
                return false;
            }
            // The pointer itself over the view first (no window manager: X sends the enter
            // and leave events a real pointer causes), then the move the view sees.
            QTest::mouseMove(view, onCloud);
            QMouseEvent move(QEvent::MouseMove, QPointF(onCloud),
                             view->mapToGlobal(QPointF(onCloud)), Qt::NoButton, Qt::NoButton,
                             Qt::NoModifier);
            QCoreApplication::sendEvent(view, &move);
            QTest::qWait(150);
            return pickLabel->text().startsWith(QStringLiteral("x "));
        };
        bool named = false; // (the hover itself may repeat: it only sets the label again)
        QTRY_VERIFY_WITH_TIMEOUT(named || (named = hoverNamesAPoint()), kBuildTimeoutMs);
        QVERIFY2(pickLabel->text().contains(QStringLiteral(" · level ")),
                 qPrintable(pickLabel->text()));
        QEvent leave(QEvent::Leave);
        QCoreApplication::sendEvent(view, &leave);
        QTRY_VERIFY(pickLabel->text().isEmpty());

        // Measure → Distance, two clicks on the cloud: the Measurements dock lists it; its
        // Delete button removes it from the view.
        auto* distance = window.findChild<QAction*>(QStringLiteral("actionMeasureDistance"));
        QVERIFY(distance != nullptr);
        distance->trigger();
        QCOMPARE(view->measureTool(), std::optional<MeasureKind>(MeasureKind::Distance));
        // Two points the current frame draws, the first and the last of a coarse scan (the
        // front refines between frames: scan again before each try).
        const auto addDrawnPoint = [&](bool last) {
            std::vector<QPoint> drawn;
            for (int y = 0; y < view->height(); y += 24) {
                for (int x = 0; x < view->width(); x += 24) {
                    if (view->pickCloudPoint(QPoint(x, y))) {
                        drawn.emplace_back(x, y);
                    }
                }
            }
            return drawn.size() >= 2 && view->addMeasurePoint(last ? drawn.back() : drawn.front());
        };
        // QTRY evaluates its condition once more after it holds: each point is added once.
        bool firstAdded = false, lastAdded = false;
        QTRY_VERIFY_WITH_TIMEOUT(firstAdded || (firstAdded = addDrawnPoint(false)), kBuildTimeoutMs);
        QTRY_VERIFY_WITH_TIMEOUT(lastAdded || (lastAdded = addDrawnPoint(true)), kBuildTimeoutMs);
        QCOMPARE(view->measurements().size(), std::size_t{1});
        QTableWidget* measured = window.measurementsPanel()->table();
        QCOMPARE(measured->rowCount(), 1);
        QCOMPARE(measured->item(0, 2)->text(), view->measurements()[0].valueText());
        measured->selectRow(0);
        window.measurementsPanel()->findChild<QPushButton*>(QStringLiteral("deleteMeasurements"))
            ->click();
        QVERIFY(view->measurements().empty());
        QCOMPARE(measured->rowCount(), 0);
        window.findChild<QAction*>(QStringLiteral("actionNavigate"))->trigger();
        QVERIFY(!view->measureTool().has_value());
        // With nothing left to refine the view stops drawing: the status bar says so rather
        // than an fps diluted by the pause; the next frame shows a rate again.
        auto* fpsLabel = window.findChild<QLabel*>(QStringLiteral("fpsLabel"));
        QVERIFY(fpsLabel != nullptr);
        QTRY_COMPARE_WITH_TIMEOUT(fpsLabel->text(), QStringLiteral("idle"), kBuildTimeoutMs);
        window.cloudView()->update();
        QTRY_VERIFY(fpsLabel->text().endsWith(QStringLiteral(" fps")));

        // Rebuild from the panel: no re-read, a deeper table.
        BuilderService* service = window.service();
        PipelineOptions deeper = window.buildPanel()->pipelineOptions();
        deeper.build.maxLevel = 9;
        window.buildPanel()->setPipelineOptions(deeper);
        window.buildPanel()->requestRebuild();
        QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 2, kBuildTimeoutMs);
        QTRY_VERIFY(!service->busy());
        QCOMPARE(service->sourceReads(), 1u);
        QCOMPARE(levels->rowCount(), 10);

        // The packed point store, chosen in the panel, applies to the next open: the same
        // hierarchy in less memory, and the panel's summary says which store it is.
        const auto exact = finished.at(1).at(0).value<PipelineResult>(); // depth 9, exact
        auto* storeCombo = window.buildPanel()->findChild<QComboBox*>(QStringLiteral("storeCombo"));
        QVERIFY(storeCombo != nullptr);
        storeCombo->setCurrentIndex(1);
        QCOMPARE(window.buildPanel()->pipelineOptions().storage, PointStorage::Packed);
        window.openFile(path);
        QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 3, kBuildTimeoutMs);
        QTRY_VERIFY(!service->busy());
        const auto packed = finished.last().at(0).value<PipelineResult>();
        QVERIFY(packed.stats.complete);
        QCOMPARE(packed.stats.pointStorage, PointStorage::Packed);
        QCOMPARE(exact.stats.pointStorage, PointStorage::Exact);
        QCOMPARE(packed.stats.totalNodes(), exact.stats.totalNodes());
        QVERIFY(packed.stats.bytesResident() < exact.stats.bytesResident());
        auto* summary = window.cutPanel()->findChild<QLabel*>(QStringLiteral("summaryLabel"));
        QVERIFY(summary != nullptr);
        QTRY_VERIFY(summary->text().contains(QStringLiteral("(packed points)")));

        window.chartsPanel()->setFollowSeconds(30.0);
        // Screenshot of the view.
        const QString shot = dir.filePath(QStringLiteral("shot.png"));
        QVERIFY(window.saveScreenshot(shot));
        QVERIFY(!QImage(shot).isNull());
        // At a chosen resolution larger than the window: drawn at that size.
        const QString large = dir.filePath(QStringLiteral("large.png"));
        QVERIFY(window.saveScreenshot(large, QSize(1600, 1200)));
        QCOMPARE(QImage(large).size(), QSize(1600, 1200));

        // A named viewpoint: saved, the camera moved away, restored exactly.
        window.cloudView()->setStandardView(StandardView::Front);
        const ViewCamera front = window.cloudView()->camera();
        window.saveViewpoint(QStringLiteral("front of the bunny"));
        QCOMPARE(window.viewpointNames(), QStringList{QStringLiteral("front of the bunny")});
        window.cloudView()->setStandardView(StandardView::Top);
        QVERIFY(window.cloudView()->camera().pitchRadians() != front.pitchRadians());
        QVERIFY(window.restoreViewpoint(QStringLiteral("front of the bunny")));
        QCOMPARE(window.cloudView()->camera().pivot(), front.pivot());
        QCOMPARE(window.cloudView()->camera().distance(), front.distance());
        QCOMPARE(window.cloudView()->camera().yawRadians(), front.yawRadians());
        QCOMPARE(window.cloudView()->camera().pitchRadians(), front.pitchRadians());
        QVERIFY(!window.restoreViewpoint(QStringLiteral("no such viewpoint")));
        window.close();
    }
    // Recent files and parameters persisted; a new window starts with them.
    MainWindow again;
    QCOMPARE(again.recentFiles().value(0), path);
    QCOMPARE(again.buildPanel()->pipelineOptions().build.maxLevel, 9);
    QCOMPARE(again.buildPanel()->pipelineOptions().storage, PointStorage::Packed);
    QCOMPARE(again.chartsPanel()->followSeconds(), 30.0);
    // Viewpoints are kept with the file: listed again when it is opened again.
    QVERIFY(again.viewpointNames().isEmpty()); // no file open yet
    again.openFile(path);
    QCOMPARE(again.viewpointNames(), QStringList{QStringLiteral("front of the bunny")});
    again.deleteViewpoint(QStringLiteral("front of the bunny"));
    QVERIFY(again.viewpointNames().isEmpty());
    QSignalSpy done(again.service(), &BuilderService::buildFinished);
    QTRY_VERIFY_WITH_TIMEOUT(done.count() == 1, kBuildTimeoutMs);
}

void TestMainWindowGL::malformedFileShowsANamedErrorAndTheAppStaysUsable() {
    QTemporaryDir dir;
    MainWindow window;
    window.show();
    QVERIFY(QTest::qWaitForWindowExposed(&window));
    QSignalSpy finished(window.service(), &BuilderService::buildFinished);
    window.openDefaultScene(30'000);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!window.service()->busy());
    const auto kept = window.service()->hierarchy();

    const QString bad = dir.filePath(QStringLiteral("broken.ply"));
    QFile file(bad);
    QVERIFY(file.open(QIODevice::WriteOnly));
    file.write("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
    file.close();
    window.openFile(bad);
    QTRY_VERIFY_WITH_TIMEOUT(window.errorDialog() != nullptr, kBuildTimeoutMs);
    QMessageBox* box = window.errorDialog();
    QVERIFY(box->isVisible());
    QVERIFY2(box->text().contains(QStringLiteral("broken.ply")), qPrintable(box->text()));
    QVERIFY2(box->informativeText().contains(bad), qPrintable(box->informativeText()));
    box->close();
    QTRY_VERIFY(window.errorDialog() == nullptr);
    // The view and the service kept the previous hierarchy; the app goes on working.
    QTRY_VERIFY(!window.service()->busy());
    QCOMPARE(window.service()->hierarchy(), kept);
    window.openDefaultScene(20'000);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 2, kBuildTimeoutMs);
    QVERIFY(finished.last().at(0).value<PipelineResult>().stats.complete);
}

// File > Save Hierarchy As, then File > Open of the .omh (pipeline 3); saving before any
// hierarchy exists is an error dialog, not a crash.
void TestMainWindowGL::savedHierarchyOpensThroughTheFileMenu() {
    QTemporaryDir dir;
    MainWindow window;
    window.show();
    const QString omh = dir.filePath(QStringLiteral("scene.omh"));
    window.saveHierarchy(omh);
    QTRY_VERIFY(window.errorDialog() != nullptr);
    window.errorDialog()->close();
    QTRY_VERIFY(window.errorDialog() == nullptr);
    QVERIFY(!QFileInfo::exists(omh));

    QSignalSpy finished(window.service(), &BuilderService::buildFinished);
    window.openDefaultScene(20'000);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!window.service()->busy());
    const auto built = finished.first().at(0).value<PipelineResult>();
    window.saveHierarchy(omh);
    QTRY_VERIFY_WITH_TIMEOUT(QFileInfo::exists(omh) && !window.service()->busy(), kBuildTimeoutMs);
    QVERIFY(window.errorDialog() == nullptr);

    window.openFile(omh);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 2, kBuildTimeoutMs);
    const auto loaded = finished.last().at(0).value<PipelineResult>();
    QCOMPARE(loaded.source.kind, PipelineKind::HierarchyFile);
    QCOMPARE(loaded.stats.levels.size(), built.stats.levels.size());
    for (std::size_t level = 0; level < built.stats.levels.size(); ++level) {
        QCOMPARE(loaded.stats.levels[level].nodes, built.stats.levels[level].nodes);
        QCOMPARE(loaded.stats.levels[level].points, built.stats.levels[level].points);
    }
    QTRY_VERIFY(window.cloudView()->hierarchy() == window.service()->hierarchy());
}

// File > Export Potree…: in the File menu, enabled once a hierarchy exists, writes the folder
// on the service's worker while the window stays responsive.
void TestMainWindowGL::potreeExportThroughTheFileMenu() {
    QTemporaryDir dir;
    MainWindow window;
    window.show();
    auto* action = window.findChild<QAction*>(QStringLiteral("actionExportPotree"));
    QVERIFY(action != nullptr);
    QVERIFY(!action->isEnabled());
    QVERIFY(window.menuBar()->actions().first()->menu()->actions().contains(action));

    QSignalSpy finished(window.service(), &BuilderService::buildFinished);
    window.openDefaultScene(20'000);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!window.service()->busy());
    QVERIFY(action->isEnabled());
    const QString folder = dir.filePath(QStringLiteral("scene-potree"));
    window.exportPotree(folder);
    QTRY_VERIFY_WITH_TIMEOUT(QFileInfo::exists(folder + QStringLiteral("/metadata.json")) &&
                                 !window.service()->busy(),
                             kBuildTimeoutMs);
    QVERIFY(window.errorDialog() == nullptr);
    QFile metadata(folder + QStringLiteral("/metadata.json"));
    QVERIFY(metadata.open(QIODevice::ReadOnly));
    QVERIFY(metadata.readAll().contains("\"points\": 20000,"));
}

// The panel's memory budget and scratch folder apply to the next open: a budget below the
// cloud's in-memory sort spills runs to the chosen folder, the hierarchy is the same, no run is
// left, and both settings come back in the next window.
void TestMainWindowGL::aCloudBeyondTheMemoryBudgetSortsOnDisk() {
    OMICRON_REQUIRE_SHARED_FILE(path, "lion.ply");
    QTemporaryDir scratch;
    {
        MainWindow window;
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        QSignalSpy finished(window.service(), &BuilderService::buildFinished);
        window.openFile(path);
        QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
        QTRY_VERIFY(!window.service()->busy());
        const auto inMemory = finished.last().at(0).value<PipelineResult>();
        QCOMPARE(inMemory.sortRuns, std::size_t{0});

        auto* budget =
            window.buildPanel()->findChild<QSpinBox*>(QStringLiteral("memoryBudgetSpin"));
        auto* folder = window.buildPanel()->findChild<QLineEdit*>(QStringLiteral("tempDirEdit"));
        QVERIFY(budget != nullptr && folder != nullptr);
        QCOMPARE(budget->text(), QStringLiteral("automatic (half of RAM)"));
        budget->setValue(4);
        folder->setText(scratch.path());
        window.openFile(path);
        QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 2, kBuildTimeoutMs);
        QTRY_VERIFY(!window.service()->busy());
        const auto spilled = finished.last().at(0).value<PipelineResult>();
        QVERIFY2(spilled.sortRuns > 1, qPrintable(QString::number(spilled.sortRuns)));
        QVERIFY(spilled.stats.complete);
        QCOMPARE(spilled.stats.totalNodes(), inMemory.stats.totalNodes());
        QCOMPARE(spilled.stats.levels.back().points, inMemory.stats.levels.back().points);
        QVERIFY(QDir(scratch.path()).isEmpty());
        window.close();
    }
    MainWindow again;
    QCOMPARE(again.buildPanel()->pipelineOptions().memoryBudgetBytes, 4 * kMiB);
    QCOMPARE(again.buildPanel()->pipelineOptions().tempDir, scratch.path().toStdString());
    // Back to automatic for the other tests.
    PipelineOptions automatic = again.buildPanel()->pipelineOptions();
    automatic.memoryBudgetBytes = 0;
    automatic.tempDir.clear();
    again.buildPanel()->setPipelineOptions(automatic);
    again.close();
}

void TestMainWindowGL::closingMidBuildReturnsPromptly() {
    std::weak_ptr<const Hierarchy> hierarchy;
    QElapsedTimer clock;
    {
        MainWindow window;
        window.show();
        QSignalSpy attached(window.service(), &BuilderService::hierarchyChanged);
        window.openDefaultScene(3'000'000);
        QTRY_VERIFY_WITH_TIMEOUT(attached.count() > 0, kBuildTimeoutMs);
        hierarchy = window.service()->hierarchy();
        QVERIFY(window.service()->busy());
        clock.start();
        window.close();
    }
    QVERIFY2(clock.elapsed() < 10'000, qPrintable(QString::number(clock.elapsed())));
    // The window, its view and the service are gone, and with them the builder and its
    // threads: nothing holds the hierarchy any more.
    QVERIFY(hierarchy.expired());
}

// View -> Render Mode and the build panel's render combo are one setting: either drives the
// view and the other follows; compute points are the default; the choice persists (and a
// settings file of the splats-or-points era still opens in splat mode).
void TestMainWindowGL::renderModeMenuAndPanelDriveTheView() {
    QSettings().remove(QStringLiteral("view"));
    {
        MainWindow window;
        auto* computeAction = window.findChild<QAction*>(QStringLiteral("actionComputePoints"));
        auto* pointsAction = window.findChild<QAction*>(QStringLiteral("actionPoints"));
        auto* splatsAction = window.findChild<QAction*>(QStringLiteral("actionSplats"));
        auto* combo = window.buildPanel()->findChild<QComboBox*>(QStringLiteral("renderModeCombo"));
        QVERIFY(computeAction && pointsAction && splatsAction && combo);
        QCOMPARE(window.cloudView()->renderSettings().mode, RenderMode::ComputePoints);
        QCOMPARE(window.buildPanel()->viewParameters().renderMode, RenderMode::ComputePoints);
        QVERIFY(computeAction->isChecked());

        pointsAction->trigger();
        QCOMPARE(window.cloudView()->renderSettings().mode, RenderMode::Points);
        QCOMPARE(combo->currentText(), QStringLiteral("GL points"));

        combo->setCurrentIndex(combo->findText(QStringLiteral("surface splats")));
        QCOMPARE(window.cloudView()->renderSettings().mode, RenderMode::Splats);
        QVERIFY(splatsAction->isChecked());
        QVERIFY(!pointsAction->isChecked());

        computeAction->trigger();
        QCOMPARE(window.cloudView()->renderSettings().mode, RenderMode::ComputePoints);
        QCOMPARE(combo->currentText(), QStringLiteral("compute points"));
        pointsAction->trigger();

        // Eye-dome lighting: auto by default; the panel turns it on and sets its shading.
        auto* edl = window.buildPanel()->findChild<QComboBox*>(QStringLiteral("edlCombo"));
        auto* strength =
            window.buildPanel()->findChild<QDoubleSpinBox*>(QStringLiteral("edlStrengthSpin"));
        QVERIFY(edl && strength);
        QCOMPARE(window.cloudView()->renderSettings().edl, EdlMode::Auto);
        edl->setCurrentIndex(edl->findText(QStringLiteral("on")));
        strength->setValue(2.5);
        QCOMPARE(window.cloudView()->renderSettings().edl, EdlMode::On);
        QCOMPARE(window.cloudView()->renderSettings().edlStrength, 2.5f);
        window.close();
    }
    {
        MainWindow again;
        QCOMPARE(again.cloudView()->renderSettings().mode, RenderMode::Points);
        QCOMPARE(again.cloudView()->renderSettings().edl, EdlMode::On);
        QCOMPARE(again.cloudView()->renderSettings().edlStrength, 2.5f);
        again.close();
    }
    QSettings().remove(QStringLiteral("view/renderMode"));
    QSettings().setValue(QStringLiteral("view/splats"), true);
    {
        MainWindow legacy;
        QCOMPARE(legacy.cloudView()->renderSettings().mode, RenderMode::Splats);
    }
    QSettings().remove(QStringLiteral("view"));
}

// The cut panel's Hierarchy box: selecting a node shows its details and draws its cell in the view
// (the widget's highlight, and magenta pixels in its frame); clearing the selection removes it. The
// same build feeds the insertion delay chart its leaf -> drawn series.
void TestMainWindowGL::hierarchyTreeSelectionHighlightsTheNodeInTheView() {
    MainWindow window;
    window.resize(1400, 900);
    window.show();
    QVERIFY(QTest::qWaitForWindowExposed(&window));
    CutPanel* panel = window.cutPanel();
    QAbstractItemModelTester tester(panel->hierarchyModel(),
                                    QAbstractItemModelTester::FailureReportingMode::QtTest);
    QSignalSpy finished(window.service(), &BuilderService::buildFinished);
    // Long enough to be drawn while it builds, also on a busy machine (the delay chart below
    // needs a leaf drawn during the build).
    window.openDefaultScene(3'000'000);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!window.service()->busy());
    QTRY_COMPARE(panel->hierarchyModel()->rowCount(), 1);

    // Leaves published after the view attached were drawn: the front insertion delay chart.
    TimeSeriesChart* delay = window.chartsPanel()->chart(QStringLiteral("Insertion delay"));
    QVERIFY(delay != nullptr);
    QTRY_VERIFY_WITH_TIMEOUT(delay->line(0)->count() > 0, kBuildTimeoutMs);
    QVERIFY(delay->line(1)->count() > 0);
    QVERIFY(delay->line(0)->points().last().y() <= delay->line(1)->points().last().y());

    CloudView* view = window.cloudView();
    const int before = test::magentaPixels(view->grabFramebuffer());
    const auto hierarchy = window.service()->hierarchy();
    const morton::Code code = hierarchy->node(1, 0).code;
    QVERIFY(panel->selectNode(code));
    QCOMPARE(view->highlightedNode(), std::optional<std::uint64_t>(code));
    QVERIFY(panel->nodeDetails().contains(QStringLiteral("0x%1").arg(code, 0, 16)));
    const int highlighted = test::magentaPixels(view->grabFramebuffer());
    QVERIFY2(highlighted > before + 100,
             qPrintable(QStringLiteral("%1 -> %2").arg(before).arg(highlighted)));

    panel->hierarchyTree()->selectionModel()->clearCurrentIndex();
    QVERIFY(!panel->selectedNode());
    QVERIFY(!view->highlightedNode());
    QCOMPARE(test::magentaPixels(view->grabFramebuffer()), before);
}

int main(int argc, char* argv[]) {
    omicron::useCoreProfileByDefault();
    QApplication app(argc, argv);
    TestMainWindowGL test;
    return QTest::qExec(&test, argc, argv);
}

#include "tst_mainwindowGL.moc"
