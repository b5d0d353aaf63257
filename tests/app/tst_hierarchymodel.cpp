// HierarchyModel over real hierarchies: the model tester while a builder publishes nodes on
// its own threads and after it finished; only settled nodes shown, the top rows grouped by
// level in Morton order; the complete hierarchy rooted at level 0 with every node reachable
// through lazily fetched children; a new hierarchy resets the model; indexOfNode fetches the
// path to a deep node; a .omh file loading top-down (pipeline 3) fills expanded rows.
#include "build/hierarchy_builder.hpp"
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "hierarchy_model.hpp"
#include "pipeline/build_pipeline.hpp"
#include "widget_test_support.hpp"

#include <QAbstractItemModelTester>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QtTest>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

using namespace omicron;

namespace {

constexpr int kTimeoutMs = 120'000;

std::shared_ptr<const Hierarchy> builtScene(std::uint64_t points, int maxLevel,
                                            BuildPipeline& pipeline) {
    PipelineOptions options;
    options.build.maxLevel = maxLevel;
    pipeline.runGeneratedScene(points, 2, options);
    return pipeline.hierarchy();
}

// Fetches the children of every row (depth first); returns the rows seen.
std::size_t expandAll(HierarchyModel& model, const QModelIndex& parent = {}) {
    std::size_t rows = 0;
    if (parent.isValid() && model.canFetchMore(parent)) {
        model.fetchMore(parent);
    }
    for (int row = 0; row < model.rowCount(parent); ++row) {
        rows += 1 + expandAll(model, model.index(row, 0, parent));
    }
    return rows;
}

// Every row shown: a published, settled node; its data is its node's; fetched children are
// its children in order; top rows by level, Morton order within a level.
void checkRows(const HierarchyModel& model, const QModelIndex& parent = {}) {
    const Hierarchy& hierarchy = *model.hierarchy();
    const PublishedCut cut = hierarchy.publishedCut(); // settledness only grows: later is fine
    int previousLevel = -1;
    morton::Code previousCode = 0;
    for (int row = 0; row < model.rowCount(parent); ++row) {
        const QModelIndex index = model.index(row, 0, parent);
        const auto node = model.node(index);
        QVERIFY(node.has_value());
        QVERIFY(node->index < hierarchy.nodeCount(node->level));
        const OctreeNode& octree = hierarchy.node(node->level, node->index);
        QVERIFY2(
            Hierarchy::isSettled(octree.code, cut, hierarchy.maxLevel()),
            qPrintable(QStringLiteral("an unsettled node is shown: 0x%1").arg(octree.code, 0, 16)));
        QCOMPARE(index.data(HierarchyModel::CodeRole).toULongLong(), quint64(octree.code));
        QCOMPARE(index.data(HierarchyModel::LevelRole).toInt(), node->level);
        QCOMPARE(model.index(row, HierarchyModel::Points, parent).data(Qt::EditRole).toULongLong(),
                 quint64(octree.pointCount));
        if (parent.isValid()) {
            const auto up = model.node(parent);
            const OctreeNode& parentNode = hierarchy.node(up->level, up->index);
            QCOMPARE(node->level, up->level + 1);
            QCOMPARE(node->index, parentNode.firstChild + static_cast<std::uint32_t>(row));
            QCOMPARE(octree.code >> 3, parentNode.code);
        } else {
            QVERIFY(node->level >= previousLevel);
            if (node->level == previousLevel) {
                QVERIFY(octree.code > previousCode);
            }
            previousLevel = node->level;
            previousCode = octree.code;
        }
        checkRows(model, index);
    }
}

std::size_t totalNodes(const Hierarchy& hierarchy) {
    std::size_t nodes = 0;
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        nodes += hierarchy.nodeCount(level);
    }
    return nodes;
}

} // namespace

class TestHierarchyModel : public QObject {
    Q_OBJECT
private slots:
    void growsWithTheBuildAndPassesTheModelTester();
    void completeHierarchyIsRootedAndHoldsEveryNode();
    void newHierarchyResetsTheModel();
    void indexOfNodeFetchesThePath();
    void fileLoadingTopDownFillsExpandedRows();
};

void TestHierarchyModel::growsWithTheBuildAndPassesTheModelTester() {
    const test::SortedScene scene = test::sortGeneratedScene(300'000, 8);
    const auto& ranges = scene.ranges;
    QVERIFY(ranges.size() >= 10);
    BuildOptions options;
    options.maxLevel = 7;
    options.worklistSize = 16;
    HierarchyBuilder builder(scene.cloud(), options);
    const auto hierarchy = builder.sharedHierarchy();

    HierarchyModel model;
    // The tester walks every fetched row on every change: attached through the build and the
    // first look at the complete tree, not while all of its thousands of rows are fetched.
    auto tester = std::make_unique<QAbstractItemModelTester>(
        &model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    model.setHierarchy(hierarchy);
    QCOMPARE(model.rowCount(), 0); // nothing settled before any input
    QSignalSpy removed(&model, &QAbstractItemModel::rowsRemoved);

    // Half the input: the builder cannot finish, and what it settles shows up.
    for (std::size_t i = 0; i < ranges.size() / 2; ++i) {
        builder.onSortedRange(*scene.cloud(), ranges[i].first, ranges[i].second);
    }
    QTRY_VERIFY_WITH_TIMEOUT((model.refresh(), model.rowCount() > 0), kTimeoutMs);
    QVERIFY(!hierarchy->publishedCut().complete);
    QCOMPARE(model.topLevelRows(0), std::size_t{0}); // levels 0 and 1 settle only at the end
    QCOMPARE(model.topLevelRows(1), std::size_t{0});
    checkRows(model);
    // Expand the first rows (children fetched lazily) before the rest of the build moves them.
    for (int row = 0; row < std::min(model.rowCount(), 20); ++row) {
        const QModelIndex index = model.index(row, 0);
        if (model.canFetchMore(index)) {
            model.fetchMore(index);
        }
    }
    checkRows(model);

    // The rest, from another thread, while the model refreshes and is walked here.
    std::atomic<bool> fed{false};
    std::thread producer([&] {
        for (std::size_t i = ranges.size() / 2; i < ranges.size(); ++i) {
            builder.onSortedRange(*scene.cloud(), ranges[i].first, ranges[i].second);
        }
        builder.finish();
        fed.store(true);
    });
    std::size_t refreshes = 0;
    while (!fed.load() || !hierarchy->publishedCut().complete) {
        model.refresh();
        ++refreshes;
        checkRows(model);
        if (model.rowCount() > 0) {
            const QModelIndex last = model.index(model.rowCount() - 1, 0);
            if (model.canFetchMore(last)) {
                model.fetchMore(last);
            }
        }
        QTest::qWait(2);
        QVERIFY(refreshes < 1'000'000);
    }
    producer.join();
    builder.wait();
    model.refresh();
    checkRows(model);
    QCOMPARE(model.rowCount(), 1);
    QCOMPARE(model.index(0, 0).data(HierarchyModel::LevelRole).toInt(), 0);
    QVERIFY(removed.count() > 0); // top rows went under the parents that settled
    tester.reset();
    QCOMPARE(expandAll(model), totalNodes(*hierarchy));
    checkRows(model);
}

void TestHierarchyModel::completeHierarchyIsRootedAndHoldsEveryNode() {
    BuildPipeline pipeline;
    const auto hierarchy = builtScene(50'000, 7, pipeline);
    HierarchyModel model;
    auto tester = std::make_unique<QAbstractItemModelTester>(
        &model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    model.setHierarchy(hierarchy);
    QCOMPARE(model.rowCount(), 1);
    const QModelIndex root = model.index(0, 0);
    QCOMPARE(root.data().toString(), QStringLiteral("L0  root"));
    QCOMPARE(model.index(0, HierarchyModel::Covered).data(Qt::EditRole).toULongLong(),
             quint64(50'000));
    QVERIFY(model.hasChildren(root));
    QCOMPARE(model.rowCount(root), 0); // lazily: nothing until fetched
    QVERIFY(model.canFetchMore(root));
    model.fetchMore(root);
    QCOMPARE(model.rowCount(root), int(hierarchy->node(0, 0).childCount));
    QVERIFY(!model.canFetchMore(root));
    tester.reset();
    QCOMPARE(expandAll(model), totalNodes(*hierarchy));
    checkRows(model);
    QVERIFY(!model.canFetchMore({})); // the top level changes in refresh() only
}

void TestHierarchyModel::newHierarchyResetsTheModel() {
    BuildPipeline first, second;
    const auto a = builtScene(20'000, 4, first);
    const auto b = builtScene(30'000, 3, second);
    HierarchyModel model;
    QAbstractItemModelTester tester(&model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    model.setHierarchy(a);
    expandAll(model);
    QSignalSpy reset(&model, &QAbstractItemModel::modelReset);
    model.setHierarchy(b);
    QCOMPARE(reset.count(), 1);
    QCOMPARE(model.rowCount(), 1);
    QCOMPARE(model.rowCount(model.index(0, 0)), 0); // b's rows are not fetched yet
    QCOMPARE(expandAll(model), totalNodes(*b));
    model.setHierarchy(nullptr);
    QCOMPARE(reset.count(), 2);
    QCOMPARE(model.rowCount(), 0);
    QVERIFY(!model.canFetchMore({}));
}

void TestHierarchyModel::indexOfNodeFetchesThePath() {
    BuildPipeline pipeline;
    const auto hierarchy = builtScene(40'000, 7, pipeline);
    HierarchyModel model;
    QAbstractItemModelTester tester(&model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    model.setHierarchy(hierarchy);
    const int level = hierarchy->maxLevel();
    const std::size_t count = hierarchy->nodeCount(level);
    QVERIFY(count > 10);
    const OctreeNode& deep = hierarchy->node(level, count / 2);
    const QModelIndex index = model.indexOfNode(deep.code);
    QVERIFY(index.isValid());
    QCOMPARE(index.data(HierarchyModel::CodeRole).toULongLong(), quint64(deep.code));
    // Its ancestors are the rows above it.
    QModelIndex up = index.parent();
    for (int l = level - 1; l >= 0; --l) {
        QVERIFY(up.isValid());
        QCOMPARE(up.data(HierarchyModel::CodeRole).toULongLong(),
                 quint64(deep.code >> (3 * (level - l))));
        up = up.parent();
    }
    QVERIFY(!up.isValid());
    QCOMPARE(model.indexOfNode(deep.code), index); // already fetched: the same row
    QVERIFY(!model.indexOfNode(0).isValid());
    QVERIFY(!model.indexOfNode(morton::encode({1, 1, 1}, level + 1)).isValid()); // too deep
    checkRows(model);
}

// A .omh file loads top-down, a level at a time: a row expanded before its children's level
// is published gets them at the refresh after it is (the loader waits at each level here, so
// the order is certain).
void TestHierarchyModel::fileLoadingTopDownFillsExpandedRows() {
    QTemporaryDir dir;
    const std::string path = dir.filePath(QStringLiteral("scene.omh")).toStdString();
    {
        BuildPipeline pipeline;
        PipelineOptions options;
        options.build.maxLevel = 4;
        const PipelineResult built = pipeline.runGeneratedScene(100'000, 4, options);
        writeOmh(path, *pipeline.hierarchy(), omhBuildInfo(options.build, built.stats));
    }
    OmhReader reader(path);
    const auto hierarchy = reader.hierarchy();
    std::mutex mutex;
    std::condition_variable changed;
    int published = -1, released = -1; // levels the loader published / may go past
    std::thread loader([&] {
        reader.load([&](int level) {
            std::unique_lock lock(mutex);
            published = level;
            changed.notify_all();
            changed.wait(lock, [&] { return released >= level; });
        });
    });
    const auto waitForLevel = [&](int level) {
        std::unique_lock lock(mutex);
        changed.wait(lock, [&] { return published >= level; });
    };
    const auto release = [&](int level) {
        std::lock_guard lock(mutex);
        released = level;
        changed.notify_all();
    };

    HierarchyModel model;
    QAbstractItemModelTester tester(&model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    waitForLevel(0);
    model.setHierarchy(hierarchy);
    QCOMPARE(model.rowCount(), 1);
    const QModelIndex root = model.index(0, 0);
    QVERIFY(model.hasChildren(root));
    QVERIFY(model.canFetchMore(root));
    model.fetchMore(root); // level 1 is not published yet: the row waits for it
    QCOMPARE(model.rowCount(root), 0);
    QVERIFY(!model.canFetchMore(root));
    release(0);
    waitForLevel(1);
    model.refresh();
    QCOMPARE(model.rowCount(root), int(hierarchy->node(0, 0).childCount));
    const QModelIndex child = model.index(0, 0, root);
    model.fetchMore(child); // level 2 is not published yet either
    QCOMPARE(model.rowCount(child), 0);
    release(1);
    waitForLevel(2);
    model.refresh();
    QCOMPARE(model.rowCount(child), int(hierarchy->node(1, 0).childCount));
    release(hierarchy->maxLevel());
    loader.join();
    model.refresh();
    QCOMPARE(model.rowCount(), 1);
    QCOMPARE(expandAll(model), totalNodes(*hierarchy));
    checkRows(model);
}

QTEST_MAIN(TestHierarchyModel)
#include "tst_hierarchymodel.moc"
