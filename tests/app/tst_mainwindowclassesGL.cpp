// MainWindow with classified clouds under a real GL context (Xvfb): the TerraScan tile opens
// coloured by class with its classes in the Classes dock, whose check box hides a class in
// the view; hovering names the point's class, return and GPS time; a cloud of classes 1-2
// (autzen_trim.las) keeps opening in RGB; a colour mode the user chose is kept.
#include "app_test_support.hpp"
#include "builder_service.hpp"
#include "class_model.hpp"
#include "classes_panel.hpp"
#include "cloud_view.hpp"
#include "main_window.hpp"
#include "widget_test_support.hpp"

#include <QAction>
#include <QDockWidget>
#include <QLabel>
#include <QMenu>
#include <QMenuBar>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QtTest>

using namespace omicron;

namespace {

constexpr int kBuildTimeoutMs = 120'000;

void openAndWait(MainWindow& window, const QString& path) {
    QSignalSpy finished(window.service(), &BuilderService::buildFinished);
    window.openFile(path);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!window.service()->busy());
}

QColor classColor(int classification) {
    const glm::u8vec3 c = lasClassColor(classification);
    return QColor(c.r, c.g, c.b);
}

QAction* colorAction(MainWindow& window, const QString& text) {
    for (QAction* action : window.findChildren<QAction*>()) {
        if (action->text().remove(QLatin1Char('&')) == text && action->isCheckable()) {
            return action;
        }
    }
    return nullptr;
}

} // namespace

class TestMainWindowClassesGL : public QObject {
    Q_OBJECT
private slots:
    void initTestCase() {
        QStandardPaths::setTestModeEnabled(true);
        QCoreApplication::setOrganizationName(QStringLiteral("omicron-tests"));
        QCoreApplication::setApplicationName(QStringLiteral("tst_mainwindowclassesGL"));
        QSettings().clear();
    }

    void aClassifiedCloudOpensColouredByClassWithItsLegend() {
        OMICRON_REQUIRE_SHARED_FILE(path, QStringLiteral("laz/terrascan_fmt8.laz"));
        MainWindow window;
        window.resize(1400, 900);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        CloudView* view = window.cloudView();
        openAndWait(window, path);

        // Classes 3-6 and 65 besides ground: coloured by class, the legend in front.
        QTRY_COMPARE_WITH_TIMEOUT(view->renderSettings().color, ColorMode::Classification,
                                  kBuildTimeoutMs);
        QVERIFY(colorAction(window, QStringLiteral("Classification"))->isChecked());
        auto* dock = window.findChild<QDockWidget*>(QStringLiteral("classesDock"));
        QVERIFY(dock != nullptr && !dock->visibleRegion().isEmpty());
        ClassesPanel* panel = window.classesPanel();
        QTRY_VERIFY_WITH_TIMEOUT(panel->counts().complete, kBuildTimeoutMs);
        QCOMPARE(panel->model()->classes(), (std::vector<int>{1, 2, 3, 4, 5, 6, 65}));
        QCOMPARE(panel->model()->count(2), quint64(683023));
        QCOMPARE(panel->model()->count(5), quint64(9003));

        // The ground (most of the tile) in its colour; unticking it hides it in the view.
        QTRY_VERIFY_WITH_TIMEOUT(
            test::pixelsNear(view->grabFramebuffer(), classColor(2), 30) > 1000, kBuildTimeoutMs);
        const double before = test::coverage(view->grabFramebuffer(), test::viewBackground());
        ClassModel* model = panel->model();
        const QModelIndex ground = model->index(1, ClassModel::ClassColumn);
        QCOMPARE(model->data(ground, Qt::DisplayRole).toInt(), 2);
        QVERIFY(model->setData(ground, Qt::Unchecked, Qt::CheckStateRole));
        QVERIFY(!view->isClassVisible(2));
        const QImage hidden = view->grabFramebuffer();
        QCOMPARE(test::pixelsNear(hidden, classColor(2), 30), 0);
        QVERIFY2(test::coverage(hidden, test::viewBackground()) < before / 4,
                 qPrintable(QStringLiteral("%1 -> %2")
                                .arg(before)
                                .arg(test::coverage(hidden, test::viewBackground()))));
        // Show all brings it back (and the box is ticked again).
        QTest::mouseClick(panel->findChild<QPushButton*>(QStringLiteral("showAllClasses")),
                          Qt::LeftButton);
        QVERIFY(view->isClassVisible(2));
        QCOMPARE(model->data(ground, Qt::CheckStateRole).toInt(), int(Qt::Checked));

        // Hovering a drawn point names its class, return and GPS time.
        auto* pickLabel = window.findChild<QLabel*>(QStringLiteral("pickLabel"));
        const auto hoverNamesAClass = [&] {
            for (int y = view->height() / 4; y < view->height() * 3 / 4; y += 16) {
                for (int x = view->width() / 4; x < view->width() * 3 / 4; x += 16) {
                    if (!view->pickCloudPoint(QPoint(x, y))) {
                        continue;
                    }
                    QTest::mouseMove(view, QPoint(x, y));
                    QMouseEvent move(QEvent::MouseMove, QPointF(x, y),
                                     view->mapToGlobal(QPointF(x, y)), Qt::NoButton, Qt::NoButton,
                                     Qt::NoModifier);
                    QCoreApplication::sendEvent(view, &move);
                    QTest::qWait(150);
                    return pickLabel->text().contains(QStringLiteral(" · class "));
                }
            }
            return false;
        };
        bool named = false;
        QTRY_VERIFY_WITH_TIMEOUT(named || (named = hoverNamesAClass()), kBuildTimeoutMs);
        const QString text = pickLabel->text();
        QVERIFY2(text.contains(QRegularExpression(
                     QStringLiteral(" · class (1 Unclassified|2 Ground|3 Low Vegetation|4 Medium "
                                    "Vegetation|5 High Vegetation|6 Building|65 User 65) · "))),
                 qPrintable(text));
        QVERIFY2(text.contains(QRegularExpression(QStringLiteral(" · return [1-6]/[1-6] · "))),
                 qPrintable(text));
        QVERIFY2(text.contains(QStringLiteral(" · GPS time ")), qPrintable(text));
    }

    void aCloudOfGroundOnlyKeepsRgbAndAChosenModeIsKept() {
        OMICRON_REQUIRE_SHARED_FILE(autzen, QStringLiteral("autzen_trim.las"));
        OMICRON_REQUIRE_SHARED_FILE(terrascan, QStringLiteral("laz/terrascan_fmt8.laz"));
        MainWindow window;
        window.resize(1200, 800);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        CloudView* view = window.cloudView();
        openAndWait(window, autzen);
        QTRY_VERIFY_WITH_TIMEOUT(window.classesPanel()->counts().complete, kBuildTimeoutMs);
        QCOMPARE(window.classesPanel()->model()->classes(), (std::vector<int>{1, 2}));
        QCOMPARE(view->renderSettings().color, ColorMode::Rgb);

        // Chosen by the user: a classified cloud opened afterwards keeps it.
        colorAction(window, QStringLiteral("Height"))->trigger();
        QCOMPARE(view->renderSettings().color, ColorMode::Height);
        openAndWait(window, terrascan);
        QTRY_VERIFY_WITH_TIMEOUT(window.classesPanel()->counts().complete, kBuildTimeoutMs);
        QCOMPARE(window.classesPanel()->model()->classes().size(), std::size_t{7});
        QCOMPARE(view->renderSettings().color, ColorMode::Height);
    }
};

int main(int argc, char* argv[]) {
    omicron::useCoreProfileByDefault();
    QApplication app(argc, argv);
    TestMainWindowClassesGL test;
    return QTest::qExec(&test, argc, argv);
}

#include "tst_mainwindowclassesGL.moc"
