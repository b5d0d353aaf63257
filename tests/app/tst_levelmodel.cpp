// LevelModel under QAbstractItemModelTester while statistics arrive, grow, change depth and
// clear; its numbers and headers.
#include "level_model.hpp"

#include <QAbstractItemModelTester>
#include <QSignalSpy>
#include <QtTest>

using namespace omicron;

namespace {

BuildStatistics statistics(int maxLevel, std::uint64_t scale) {
    BuildStatistics s;
    s.levels.resize(static_cast<std::size_t>(maxLevel) + 1);
    for (int level = 0; level <= maxLevel; ++level) {
        LevelStatistics& row = s.levels[static_cast<std::size_t>(level)];
        row.nodes = scale * (std::uint64_t{1} << level);
        row.leaves = level == maxLevel ? row.nodes : 0;
        row.points = row.nodes * 10;
        row.cutRoots = static_cast<std::uint64_t>(maxLevel - level);
        row.placeholdersPending = level % 2;
        row.placeholdersSubstituted = scale + static_cast<std::uint64_t>(level);
    }
    return s;
}

} // namespace

class TestLevelModel : public QObject {
    Q_OBJECT
private slots:
    void passesTheModelTesterThroughABuild();
    void reportsTheNumbersOfEachLevel();
    void unchangedRowsEmitNothing();
    void frontNodesFillTheirColumn();
};

void TestLevelModel::passesTheModelTesterThroughABuild() {
    LevelModel model;
    QAbstractItemModelTester tester(&model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    QCOMPARE(model.rowCount(), 0);
    model.setStatistics(statistics(7, 1));
    QCOMPARE(model.rowCount(), 8);
    QCOMPARE(model.columnCount(), int(LevelModel::ColumnCount));
    model.setStatistics(statistics(7, 2));
    model.setStatistics(statistics(9, 2)); // a rebuild with another depth
    QCOMPARE(model.rowCount(), 10);
    model.setStatistics(statistics(3, 1));
    QCOMPARE(model.rowCount(), 4);
    model.clear();
    QCOMPARE(model.rowCount(), 0);
    model.setStatistics(statistics(5, 4));
    QCOMPARE(model.rowCount(), 6);
}

void TestLevelModel::reportsTheNumbersOfEachLevel() {
    LevelModel model;
    model.setStatistics(statistics(6, 3));
    QCOMPARE(model.value(4, LevelModel::Nodes), quint64(3 * 16));
    QCOMPARE(model.index(4, LevelModel::Nodes).data(Qt::EditRole).toULongLong(), quint64(48));
    QCOMPARE(model.index(6, LevelModel::Leaves).data(Qt::EditRole).toULongLong(), quint64(3 * 64));
    QCOMPARE(model.index(2, LevelModel::CutRoots).data(Qt::EditRole).toULongLong(), quint64(4));
    QCOMPARE(model.index(3, LevelModel::PlaceholdersPending).data(Qt::EditRole).toULongLong(),
             quint64(1));
    QCOMPARE(model.index(5, LevelModel::PlaceholdersSubstituted).data(Qt::EditRole).toULongLong(),
             quint64(8));
    QCOMPARE(model.index(5, LevelModel::Level).data().toString(), QStringLiteral("5"));
    QCOMPARE(model.index(6, LevelModel::Points).data(Qt::EditRole).toULongLong(),
             quint64(3 * 64 * 10));
    QCOMPARE(model.headerData(LevelModel::CutRoots, Qt::Horizontal).toString(),
             QStringLiteral("Roots"));
    QVERIFY(
        !model.headerData(LevelModel::Nodes, Qt::Horizontal, Qt::ToolTipRole).toString().isEmpty());
    QVERIFY(!model.headerData(0, Qt::Vertical).isValid());
}

void TestLevelModel::unchangedRowsEmitNothing() {
    LevelModel model;
    model.setStatistics(statistics(5, 1));
    QSignalSpy changed(&model, &QAbstractItemModel::dataChanged);
    QSignalSpy reset(&model, &QAbstractItemModel::modelReset);
    model.setStatistics(statistics(5, 1));
    QCOMPARE(changed.count(), 0);
    BuildStatistics one = statistics(5, 1);
    one.levels[3].points += 1;
    model.setStatistics(one);
    QCOMPARE(changed.count(), 1);
    QCOMPARE(changed.first().at(0).toModelIndex().row(), 3);
    QCOMPARE(reset.count(), 0);
}

// The view's front per level: its own column, changed cells only, kept for deeper levels
// until the statistics of a deeper build add their rows.
void TestLevelModel::frontNodesFillTheirColumn() {
    LevelModel model;
    QAbstractItemModelTester tester(&model, QAbstractItemModelTester::FailureReportingMode::QtTest);
    model.setStatistics(statistics(3, 1));
    QSignalSpy changed(&model, &QAbstractItemModel::dataChanged);
    const std::vector<std::size_t> front{1, 0, 12, 40, 0, 7}; // levels 4, 5: not in the table yet
    model.setFrontNodes(front);
    QCOMPARE(changed.count(), 3); // levels 0, 2 and 3
    for (const QList<QVariant>& signal : changed) {
        QCOMPARE(signal.at(0).toModelIndex().column(), int(LevelModel::FrontNodes));
        QCOMPARE(signal.at(1).toModelIndex().column(), int(LevelModel::FrontNodes));
    }
    QCOMPARE(model.value(3, LevelModel::FrontNodes), quint64(40));
    QCOMPARE(model.index(2, LevelModel::FrontNodes).data(Qt::EditRole).toULongLong(), quint64(12));
    QCOMPARE(model.headerData(LevelModel::FrontNodes, Qt::Horizontal).toString(),
             QStringLiteral("Front"));
    changed.clear();
    model.setFrontNodes(front);
    QCOMPARE(changed.count(), 0);
    model.setStatistics(statistics(5, 1)); // a deeper build: its rows show what was kept
    QCOMPARE(model.value(5, LevelModel::FrontNodes), quint64(7));
    model.setFrontNodes(std::vector<std::size_t>{1}); // a shorter front: the rest is 0
    QCOMPARE(model.value(3, LevelModel::FrontNodes), quint64(0));
    QCOMPARE(model.value(0, LevelModel::FrontNodes), quint64(1));
}

QTEST_MAIN(TestLevelModel)
#include "tst_levelmodel.moc"
