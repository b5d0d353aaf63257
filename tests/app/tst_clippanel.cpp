// ClipPanel: the fields make the clip box (box or section), fit to the cloud, centre on the
// picked point, and every change is signalled once.
#include "clip_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QPushButton>
#include <QSignalSpy>
#include <QtTest>
#include <cmath>

using namespace omicron;

class TestClipPanel : public QObject {
    Q_OBJECT
private slots:
    void fieldsMakeABoxOrASection();
};

void TestClipPanel::fieldsMakeABoxOrASection() {
    ClipPanel panel;
    QSignalSpy changed(&panel, &ClipPanel::clipChanged);
    panel.setCloudBounds({100.0, 200.0, 0.0}, {140.0, 260.0, 30.0});
    QVERIFY(!panel.clip().has_value()); // off until asked
    panel.findChild<QCheckBox*>(QStringLiteral("clipEnabled"))->setChecked(true);
    auto box = panel.clip();
    QVERIFY(box.has_value());
    // A new cloud starts the fields around it.
    QCOMPARE(box->center, glm::dvec3(120.0, 230.0, 15.0));
    QCOMPARE(box->halfSize, glm::dvec3(20.0, 30.0, 15.0));
    QVERIFY(changed.count() >= 1);
    QVERIFY(changed.last().at(0).value<std::optional<ClipBox>>().has_value());

    // A 2-unit section through a picked point, turned 30 degrees.
    panel.setPickedPoint({110.0, 250.0, 5.0});
    panel.findChild<QPushButton*>(QStringLiteral("clipCenterPicked"))->click();
    panel.findChild<QComboBox*>(QStringLiteral("clipMode"))->setCurrentIndex(1);
    panel.findChild<QDoubleSpinBox*>(QStringLiteral("clipSizeX"))->setValue(2.0);
    panel.findChild<QDoubleSpinBox*>(QStringLiteral("clipYaw"))->setValue(30.0);
    box = panel.clip();
    QCOMPARE(box->center, glm::dvec3(110.0, 250.0, 5.0));
    QCOMPARE(box->halfSize.x, 1.0);
    QVERIFY(box->halfSize.y >= ClipPanel::kSectionHalfExtent);
    QVERIFY(std::abs(box->yawRadians - std::acos(-1.0) / 6.0) < 1e-12);
    QVERIFY(box->contains({110.0 + 0.8 * std::cos(0.5236), 250.0 + 0.8 * std::sin(0.5236), 5.0}));
    QVERIFY(!box->contains({110.0 + 1.2 * std::cos(0.5236), 250.0 + 1.2 * std::sin(0.5236), 5.0}));
    QVERIFY(box->contains({110.0 - 500.0 * std::sin(0.5236), 250.0 + 500.0 * std::cos(0.5236), 90.0}));

    // Fit to the cloud: a box around it again.
    panel.findChild<QComboBox*>(QStringLiteral("clipMode"))->setCurrentIndex(0);
    const int before = changed.count();
    panel.findChild<QPushButton*>(QStringLiteral("clipFit"))->click();
    QCOMPARE(changed.count(), before + 2); // centre, then size: one signal each
    QCOMPARE(panel.clip()->halfSize, glm::dvec3(20.0, 30.0, 15.0));
    panel.findChild<QCheckBox*>(QStringLiteral("clipEnabled"))->setChecked(false);
    QVERIFY(!changed.last().at(0).value<std::optional<ClipBox>>().has_value());
}

QTEST_MAIN(TestClipPanel)
#include "tst_clippanel.moc"
