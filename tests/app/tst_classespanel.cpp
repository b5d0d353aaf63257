// ClassesPanel, ClassModel and ClassCounter without GL: the classes of a generated classified
// LAS and of the shared TerraScan tile counted off the GUI thread (model checked by
// QAbstractItemModelTester), the check boxes and Show all / Hide all, a rebuild over the same
// sorted points keeping the count, another cloud starting over.
#include "app_test_support.hpp"
#include "build/hierarchy.hpp"
#include "class_counter.hpp"
#include "class_model.hpp"
#include "classes_panel.hpp"
#include "widget_test_support.hpp"

#include <QAbstractItemModelTester>
#include <QLabel>
#include <QPushButton>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QtTest>

using namespace omicron;

namespace {

std::shared_ptr<const Hierarchy> classifiedHierarchy() {
    QTemporaryDir dir;
    const QString path = dir.filePath(QStringLiteral("classified.las"));
    test::writeClassifiedLas(path);
    return test::buildHierarchy(path, BuildOptions{});
}

} // namespace

class TestClassesPanel : public QObject {
    Q_OBJECT
private slots:
    void listsTheClassesWithTheirCounts() {
        ClassesPanel panel;
        QAbstractItemModelTester tester(panel.model(),
                                        QAbstractItemModelTester::FailureReportingMode::QtTest);
        panel.setHierarchy(classifiedHierarchy());
        QTRY_VERIFY(panel.counts().complete);
        QCOMPARE(panel.model()->classes(), (std::vector<int>{2, 6}));
        QCOMPARE(panel.model()->count(2), quint64(test::kClassifiedLasPointsPerClass));
        QCOMPARE(panel.model()->count(6), quint64(test::kClassifiedLasPointsPerClass));
        ClassModel* model = panel.model();
        QCOMPARE(model->rowCount(), 2);
        QCOMPARE(model->data(model->index(1, ClassModel::ClassColumn), Qt::DisplayRole).toInt(), 6);
        QCOMPARE(model->data(model->index(1, ClassModel::NameColumn), Qt::DisplayRole).toString(),
                 QStringLiteral("Building"));
        const glm::u8vec3 building = lasClassColor(6);
        QCOMPARE(model->data(model->index(1, ClassModel::ClassColumn), Qt::DecorationRole)
                     .value<QColor>(),
                 QColor(building.r, building.g, building.b));
        QCOMPARE(model->data(model->index(0, ClassModel::PointsColumn), Qt::DisplayRole).toString(),
                 QLocale().toString(test::kClassifiedLasPointsPerClass));
        QVERIFY(panel.findChild<QLabel*>(QStringLiteral("classesSummary"))
                    ->text()
                    .contains(QStringLiteral("2 class")));
    }

    void checkBoxesAndButtonsShowAndHideClasses() {
        ClassesPanel panel;
        QAbstractItemModelTester tester(panel.model(),
                                        QAbstractItemModelTester::FailureReportingMode::QtTest);
        panel.setHierarchy(classifiedHierarchy());
        QTRY_VERIFY(panel.counts().complete);
        ClassModel* model = panel.model();
        const QModelIndex building = model->index(1, ClassModel::ClassColumn);
        QVERIFY(model->flags(building) & Qt::ItemIsUserCheckable);
        QCOMPARE(model->data(building, Qt::CheckStateRole).toInt(), int(Qt::Checked));

        QSignalSpy visibility(&panel, &ClassesPanel::classVisibilityChanged);
        QVERIFY(model->setData(building, Qt::Unchecked, Qt::CheckStateRole));
        QCOMPARE(visibility.count(), 1);
        QCOMPARE(visibility.first().at(0).toInt(), 6);
        QCOMPARE(visibility.first().at(1).toBool(), false);
        QCOMPARE(model->data(building, Qt::CheckStateRole).toInt(), int(Qt::Unchecked));

        // The view's hidden set is what the boxes show.
        std::bitset<kLasClassCount> hidden;
        hidden.set(2);
        panel.setHiddenClasses(hidden);
        QCOMPARE(model->data(model->index(0, 0), Qt::CheckStateRole).toInt(), int(Qt::Unchecked));
        QCOMPARE(model->data(building, Qt::CheckStateRole).toInt(), int(Qt::Checked));

        QSignalSpy all(&panel, &ClassesPanel::allClassesHidden);
        QTest::mouseClick(panel.findChild<QPushButton*>(QStringLiteral("hideAllClasses")),
                          Qt::LeftButton);
        QTest::mouseClick(panel.findChild<QPushButton*>(QStringLiteral("showAllClasses")),
                          Qt::LeftButton);
        QCOMPARE(all.count(), 2);
        QCOMPARE(all.at(0).at(0).toBool(), true);
        QCOMPARE(all.at(1).at(0).toBool(), false);
    }

    void aRebuildKeepsTheCountAndAnotherCloudStartsOver() {
        ClassCounter counter;
        const auto first = classifiedHierarchy();
        counter.setHierarchy(first);
        QTRY_VERIFY(counter.snapshot().complete);
        const ClassCounter::Snapshot counted = counter.snapshot();
        QCOMPARE(counted.counted, quint64(2 * test::kClassifiedLasPointsPerClass));
        QVERIFY(counted.hasClasses);
        // Another hierarchy over the same sorted points (what Rebuild makes).
        auto rebuilt = std::make_shared<Hierarchy>(first->sharedCloud(), first->maxLevel());
        counter.setHierarchy(rebuilt);
        QCOMPARE(counter.snapshot().counts, counted.counts);
        QVERIFY(counter.snapshot().complete);
        // Another cloud: from zero, then its own counts.
        counter.setHierarchy(classifiedHierarchy());
        QTRY_VERIFY(counter.snapshot().complete);
        QCOMPARE(counter.snapshot().counts, counted.counts);
        counter.setHierarchy(nullptr);
        QCOMPARE(counter.snapshot().total, quint64(0));
    }

    void aUniformLasColumnCountsEveryPointInItsClass() {
        QTemporaryDir dir;
        const QString path = dir.filePath(QStringLiteral("one_class.las"));
        test::writeClassifiedLas(path, true);
        const auto hierarchy = test::buildHierarchy(path, BuildOptions{});
        QVERIFY(hierarchy->cloud().uniformLasColumn()); // stored once, read for every point
        ClassesPanel panel;
        panel.setHierarchy(hierarchy);
        QTRY_VERIFY(panel.counts().complete);
        QCOMPARE(panel.model()->classes(), (std::vector<int>{6}));
        QCOMPARE(panel.model()->count(6), quint64(2 * test::kClassifiedLasPointsPerClass));
    }

    void sharedTerraScanTileCountsEveryClass() {
        OMICRON_REQUIRE_SHARED_FILE(path, QStringLiteral("laz/terrascan_fmt8.laz"));
        ClassesPanel panel;
        QAbstractItemModelTester tester(panel.model(),
                                        QAbstractItemModelTester::FailureReportingMode::QtTest);
        panel.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        QTRY_VERIFY_WITH_TIMEOUT(panel.counts().complete, 60'000);
        // As `omicron-cli info` lists them (ASPRS classes 1-6 and the user class 65).
        QCOMPARE(panel.model()->classes(), (std::vector<int>{1, 2, 3, 4, 5, 6, 65}));
        const std::pair<int, quint64> expected[] = {{1, 3262}, {2, 683023}, {3, 960}, {4, 873},
                                                    {5, 9003}, {6, 590},    {65, 10}};
        for (const auto& [classification, points] : expected) {
            QCOMPARE(panel.model()->count(classification), points);
        }
        QCOMPARE(panel.counts().counted, quint64(697721));
    }
};

QTEST_MAIN(TestClassesPanel)
#include "tst_classespanel.moc"
