// MeasurementsPanel: the list of the view's measurements, copy as tab-separated text, delete,
// and CSV export (atomic, errors that name the file).
#include "measurements_panel.hpp"

#include <QFile>
#include <QPushButton>
#include <QSignalSpy>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QtTest>

using namespace omicron;

namespace {

std::vector<Measurement> twoMeasurements() {
    Measurement distance;
    distance.kind = MeasureKind::Distance;
    distance.points = {{500000.0, 4000000.0, 100.0}, {500003.0, 4000004.0, 100.0}};
    Measurement area;
    area.kind = MeasureKind::Area;
    area.points = {{0, 0, 0}, {2, 0, 0}, {2, 3, 1}};
    area.finish();
    return {distance, area};
}

} // namespace

class TestMeasurementsPanel : public QObject {
    Q_OBJECT
private slots:
    void listsCopiesAndDeletes();
    void exportsCsvAndNamesTheFileOnError();
};

void TestMeasurementsPanel::listsCopiesAndDeletes() {
    MeasurementsPanel panel;
    panel.setMeasurements(twoMeasurements());
    QTableWidget* table = panel.table();
    QCOMPARE(table->rowCount(), 2);
    QCOMPARE(table->item(0, 1)->text(), QStringLiteral("distance"));
    QCOMPARE(table->item(0, 2)->text(), QStringLiteral("5.000"));
    QVERIFY(table->item(1, 2)->text().startsWith(QStringLiteral("3.000 (area")));
    QVERIFY(table->item(0, 3)->text().contains(QStringLiteral("500003.0000 4000004.0000")));
    // Nothing selected: everything, one row per point, after a header.
    QStringList lines = panel.selectionText().split('\n', Qt::SkipEmptyParts);
    QCOMPARE(lines.size(), 1 + 2 + 3);
    QCOMPARE(lines.at(0), QStringLiteral("measurement\tkind\tvalue\tpoint\tx\ty\tz"));
    QCOMPARE(lines.at(2),
             QStringLiteral("1\tdistance\t5.000000\t2\t500003.0000\t4000004.0000\t100.0000"));
    table->selectRow(1);
    lines = panel.selectionText().split('\n', Qt::SkipEmptyParts);
    QCOMPARE(lines.size(), 1 + 3);
    QVERIFY(lines.at(1).startsWith(QStringLiteral("2\tarea\t3.000000\t1\t")));
    QSignalSpy removed(&panel, &MeasurementsPanel::removeRequested);
    panel.findChild<QPushButton*>(QStringLiteral("deleteMeasurements"))->click();
    QCOMPARE(removed.count(), 1);
    QCOMPARE(removed.first().at(0).value<std::vector<std::size_t>>(), std::vector<std::size_t>{1});
}

void TestMeasurementsPanel::exportsCsvAndNamesTheFileOnError() {
    QTemporaryDir dir;
    MeasurementsPanel panel;
    panel.setMeasurements(twoMeasurements());
    const QString path = dir.filePath(QStringLiteral("m.csv"));
    QString error;
    QVERIFY2(panel.exportCsv(path, &error), qPrintable(error));
    QFile file(path);
    QVERIFY(file.open(QIODevice::ReadOnly | QIODevice::Text));
    const QStringList lines = QString::fromUtf8(file.readAll()).split('\n', Qt::SkipEmptyParts);
    QCOMPARE(lines.size(), 6);
    QCOMPARE(lines.at(0), QStringLiteral("measurement,kind,value,point,x,y,z"));
    QCOMPARE(lines.at(5), QStringLiteral("2,area,3.000000,3,2.0000,3.0000,1.0000"));
    const QString bad = QStringLiteral("/nonexistent-folder/m.csv");
    QVERIFY(!panel.exportCsv(bad, &error));
    QVERIFY2(error.contains(bad), qPrintable(error));
}

QTEST_MAIN(TestMeasurementsPanel)
#include "tst_measurementspanel.moc"
