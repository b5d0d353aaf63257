// CutPanel: the Hierarchy box's tree and details (selecting a node shows its code, level, cell
// in source units, points held and covered, children, and emits nodeSelected for the view's
// highlight; a new hierarchy clears it), a selection that survives its row moving under a
// parent that settles while a build runs, and the read bar during a bounds pre-pass.
#include "build/hierarchy_builder.hpp"
#include "cut_panel.hpp"
#include "hierarchy_model.hpp"
#include "level_model.hpp"
#include "pipeline/build_pipeline.hpp"
#include "widget_test_support.hpp"

#include <QAbstractItemModelTester>
#include <QLabel>
#include <QLocale>
#include <QSignalSpy>
#include <QTreeView>
#include <QtTest>
#include <thread>

using namespace omicron;

namespace {

constexpr int kTimeoutMs = 120'000;

std::shared_ptr<const Hierarchy> builtScene(std::uint64_t points, int maxLevel) {
    BuildPipeline pipeline; // the hierarchy outlives it (shared)
    PipelineOptions options;
    options.build.maxLevel = maxLevel;
    pipeline.runGeneratedScene(points, 6, options);
    return pipeline.hierarchy();
}

} // namespace

class TestCutPanel : public QObject {
    Q_OBJECT
private slots:
    void selectingANodeShowsItsDetailsAndEmitsIt();
    void selectionFollowsItsRowWhileABuildRuns();
    void readBarShowsTheBoundsPrePass();
    void phaseSaysWhenTheSortSpillsAndMerges();
};

void TestCutPanel::selectingANodeShowsItsDetailsAndEmitsIt() {
    const auto hierarchy = builtScene(40'000, 6);
    CutPanel panel;
    panel.show();
    QAbstractItemModelTester tester(panel.hierarchyModel(),
                                    QAbstractItemModelTester::FailureReportingMode::QtTest);
    QSignalSpy selected(&panel, &CutPanel::nodeSelected);
    QSignalSpy cleared(&panel, &CutPanel::nodeSelectionCleared);
    panel.setHierarchy(hierarchy);
    QCOMPARE(panel.hierarchyModel()->rowCount(), 1);

    // A level-2 node, selected as the window does from code (the tree expands to it).
    QVERIFY(hierarchy->nodeCount(2) > 3);
    const OctreeNode& node = hierarchy->node(2, 3);
    QVERIFY(panel.selectNode(node.code));
    QCOMPARE(panel.selectedNode(), std::optional<morton::Code>(node.code));
    QCOMPARE(selected.count(), 1);
    QCOMPARE(selected.first().at(0).toInt(), 2);
    QCOMPARE(selected.first().at(1).toULongLong(), quint64(node.code));
    QVERIFY(panel.hierarchyTree()->isExpanded(panel.hierarchyTree()->currentIndex().parent()));
    const QString details = panel.nodeDetails();
    QVERIFY2(details.contains(QStringLiteral("0x%1").arg(node.code, 0, 16)), qPrintable(details));
    QVERIFY(details.contains(octantPath(node.code)));
    QVERIFY(details.contains(QLocale().toString(node.pointCount)));
    QVERIFY(details.contains(QLocale().toString(node.coveredCount)));
    // The cell's minimum corner in source units (metres of the generated scene).
    const CubeTransform& cube = hierarchy->cloud().cube();
    const morton::Cell cell = morton::decode(node.code);
    const glm::dvec3 low = cube.origin + glm::dvec3(cell.x, cell.y, cell.z) * (cube.edge / 4.0);
    QVERIFY2(details.contains(QStringLiteral("(%1, %2, %3)")
                                  .arg(low.x, 0, 'f', 3)
                                  .arg(low.y, 0, 'f', 3)
                                  .arg(low.z, 0, 'f', 3)),
             qPrintable(details));

    // A click on the root row: the user's selection.
    panel.hierarchyTree()->selectionModel()->setCurrentIndex(panel.hierarchyModel()->index(0, 0),
                                                             QItemSelectionModel::ClearAndSelect);
    QCOMPARE(selected.count(), 2);
    QCOMPARE(selected.last().at(0).toInt(), 0);
    QVERIFY(panel.nodeDetails().contains(QStringLiteral("root")));
    QVERIFY(!panel.selectNode(morton::encode({0, 0, 0}, 7))); // deeper than the hierarchy

    // A new hierarchy: no selection.
    panel.setHierarchy(builtScene(10'000, 5));
    QCOMPARE(cleared.count(), 1);
    QVERIFY(!panel.selectedNode());
    QVERIFY(!panel.nodeDetails().contains(QStringLiteral("0x")));
}

void TestCutPanel::selectionFollowsItsRowWhileABuildRuns() {
    const test::SortedScene scene = test::sortGeneratedScene(300'000, 9);
    const auto& ranges = scene.ranges;
    BuildOptions options;
    options.maxLevel = 7;
    HierarchyBuilder builder(scene.cloud(), options);
    const auto hierarchy = builder.sharedHierarchy();

    CutPanel panel;
    panel.show();
    panel.setHierarchy(hierarchy);
    for (std::size_t i = 0; i < ranges.size() / 2; ++i) {
        builder.onSortedRange(*scene.cloud(), ranges[i].first, ranges[i].second);
    }
    HierarchyModel& model = *panel.hierarchyModel();
    QTRY_VERIFY_WITH_TIMEOUT((panel.refreshHierarchy(), model.rowCount() > 0), kTimeoutMs);
    // The first top row: a settled node whose parent has not settled, so it will move.
    const QModelIndex first = model.index(0, 0);
    const morton::Code code = first.data(HierarchyModel::CodeRole).toULongLong();
    QVERIFY(first.data(HierarchyModel::LevelRole).toInt() >= 2);
    QSignalSpy selected(&panel, &CutPanel::nodeSelected);
    QSignalSpy cleared(&panel, &CutPanel::nodeSelectionCleared);
    panel.hierarchyTree()->selectionModel()->setCurrentIndex(first,
                                                             QItemSelectionModel::ClearAndSelect);
    QCOMPARE(selected.count(), 1);

    std::thread producer([&] {
        for (std::size_t i = ranges.size() / 2; i < ranges.size(); ++i) {
            builder.onSortedRange(*scene.cloud(), ranges[i].first, ranges[i].second);
        }
        builder.finish();
    });
    QTRY_VERIFY_WITH_TIMEOUT((panel.refreshHierarchy(), hierarchy->publishedCut().complete),
                             kTimeoutMs);
    producer.join();
    builder.wait();
    panel.refreshHierarchy();
    QCOMPARE(model.rowCount(), 1); // the root alone: the selected row moved below it
    QCOMPARE(panel.selectedNode(), std::optional<morton::Code>(code));
    const QModelIndex current = panel.hierarchyTree()->currentIndex();
    QCOMPARE(current.data(HierarchyModel::CodeRole).toULongLong(), quint64(code));
    QVERIFY(current.parent().isValid());
    QCOMPARE(cleared.count(), 0);
    for (const QList<QVariant>& signal : selected) {
        QCOMPARE(signal.at(1).toULongLong(), quint64(code)); // never another node
    }
}

void TestCutPanel::readBarShowsTheBoundsPrePass() {
    CutPanel panel;
    PipelineProgress progress;
    progress.generation = 1;
    progress.phase = BuildPhase::Opening;
    progress.bytesToScan = 8u << 20;
    progress.bytesScanned = 2u << 20;
    panel.setProgress(progress);
    QCOMPARE(panel.barValue(0), 250);
    QVERIFY2(panel.barText(0).contains(QStringLiteral("scanning bounds")),
             qPrintable(panel.barText(0)));
    progress.phase = BuildPhase::Reading;
    progress.pointsTotal = 1000;
    progress.pointsRead = 100;
    panel.setProgress(progress);
    QCOMPARE(panel.barValue(0), 100);
    QVERIFY(!panel.barText(0).contains(QStringLiteral("scanning")));
}

void TestCutPanel::phaseSaysWhenTheSortSpillsAndMerges() {
    CutPanel panel;
    auto* phase = panel.findChild<QLabel*>(QStringLiteral("phaseLabel"));
    QVERIFY(phase != nullptr);
    PipelineProgress progress;
    progress.generation = 1;
    progress.phase = BuildPhase::Reading;
    progress.pointsTotal = 1000;
    panel.setProgress(progress);
    QCOMPARE(phase->text(), QStringLiteral("reading"));
    progress.sortRuns = 3;
    panel.setProgress(progress);
    QCOMPARE(phase->text(),
             QStringLiteral("reading: beyond the memory budget, 3 sorted run(s) spilled to disk"));
    progress.phase = BuildPhase::Sorting;
    panel.setProgress(progress);
    QCOMPARE(phase->text(), QStringLiteral("merging 3 sorted run(s) from disk"));
    progress.sortRuns = 0;
    panel.setProgress(progress);
    QCOMPARE(phase->text(), QStringLiteral("sorting"));
}

QTEST_MAIN(TestCutPanel)
#include "tst_cutpanel.moc"
