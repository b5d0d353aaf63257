// CloudView's LAS colour modes and per-class visibility under a real GL context (Xvfb + Mesa
// llvmpipe in CI), on a generated classified LAS (two classes side by side, four returns, a
// GPS-time ramp): class colours drawn, a hidden class's pixels gone in every render mode,
// the return-number and GPS-time modes, the fallback without a LAS column, the pick's fields.
#include "cloud_view.hpp"
#include "widget_test_support.hpp"

#include <QFile>
#include <QTemporaryDir>
#include <QTextStream>
#include <QtTest>
#include <cmath>

using namespace omicron;

Q_DECLARE_METATYPE(omicron::RenderMode)

namespace {

constexpr QSize kImageSize(400, 400);

QColor classColor(int classification) {
    const glm::u8vec3 c = lasClassColor(classification);
    return QColor(c.r, c.g, c.b);
}

// Plain settings: no overlays, no eye-dome lighting (it would darken the colours compared).
RenderSettings plainSettings(RenderMode mode, ColorMode color) {
    RenderSettings settings;
    settings.mode = mode;
    settings.color = color;
    settings.edl = EdlMode::Off;
    settings.showAxes = false;
    settings.showBoundingBox = false;
    settings.showCutBoundary = false;
    settings.showScaleBar = false;
    settings.showNorthArrow = false;
    settings.pointBudget = 0;
    return settings;
}

std::shared_ptr<const Hierarchy> classifiedHierarchy() {
    QTemporaryDir dir;
    const QString path = dir.filePath(QStringLiteral("classified.las"));
    test::writeClassifiedLas(path);
    return test::buildHierarchy(path, BuildOptions{});
}

QImage render(CloudView& view, const RenderSettings& settings) {
    view.setRenderSettings(settings);
    return view.renderImage(kImageSize);
}

} // namespace

class tst_ClassificationGL : public QObject {
    Q_OBJECT
private:
    std::shared_ptr<const Hierarchy> m_hierarchy;

    void renderModes() {
        QTest::addColumn<RenderMode>("mode");
        QTest::newRow("compute points") << RenderMode::ComputePoints;
        QTest::newRow("GL points") << RenderMode::Points;
        QTest::newRow("splats") << RenderMode::Splats;
    }

private slots:
    void initTestCase() {
        m_hierarchy = classifiedHierarchy();
        QVERIFY(m_hierarchy != nullptr);
        QVERIFY(m_hierarchy->cloud().attributes().has(Attribute::Las));
        QVERIFY(m_hierarchy->cloud().attributes().has(Attribute::GpsTime));
    }

    void classesDrawInTheirColours_data() { renderModes(); }
    void classesDrawInTheirColours() {
        QFETCH(RenderMode, mode);
        CloudView view;
        view.setHierarchy(m_hierarchy);
        view.setStandardView(StandardView::Top);
        const QImage image = render(view, plainSettings(mode, ColorMode::Classification));
        QVERIFY(!image.isNull());
        const int ground = test::pixelsNear(image, classColor(2));
        const int building = test::pixelsNear(image, classColor(6));
        const int covered =
            static_cast<int>(test::coverage(image, test::viewBackground()) * 400 * 400);
        // Two halves of one grid: each class about half of what is drawn, nothing else.
        QVERIFY2(ground > covered / 4 && building > covered / 4,
                 qPrintable(QStringLiteral("ground %1 building %2 covered %3")
                                .arg(ground)
                                .arg(building)
                                .arg(covered)));
        QVERIFY2(ground + building > covered * 9 / 10,
                 qPrintable(QStringLiteral("ground %1 building %2 covered %3")
                                .arg(ground)
                                .arg(building)
                                .arg(covered)));
    }

    // Every LAS record the same: the sorted cloud stores the column once, and every point
    // still draws in its class's colour.
    void aCloudOfOneClassDrawsInItsColour() {
        QTemporaryDir dir;
        const QString path = dir.filePath(QStringLiteral("one_class.las"));
        test::writeClassifiedLas(path, true);
        const auto hierarchy = test::buildHierarchy(path, BuildOptions{});
        QVERIFY(hierarchy->cloud().uniformLasColumn());
        CloudView view;
        view.setHierarchy(hierarchy);
        view.setStandardView(StandardView::Top);
        const QImage image =
            render(view, plainSettings(RenderMode::ComputePoints, ColorMode::Classification));
        const int building = test::pixelsNear(image, classColor(6));
        const int covered =
            static_cast<int>(test::coverage(image, test::viewBackground()) * 400 * 400);
        QVERIFY2(covered > 0 && building > covered * 9 / 10,
                 qPrintable(QStringLiteral("building %1 covered %2").arg(building).arg(covered)));
        QCOMPARE(test::pixelsNear(image, classColor(2)), 0);
    }

    void hidingAClassRemovesExactlyItsPixels_data() { renderModes(); }
    void hidingAClassRemovesExactlyItsPixels() {
        QFETCH(RenderMode, mode);
        CloudView view;
        view.setHierarchy(m_hierarchy);
        view.setStandardView(StandardView::Top);
        RenderSettings settings = plainSettings(mode, ColorMode::Classification);
        const QImage all = render(view, settings);
        const double allCoverage = test::coverage(all, test::viewBackground());
        const int groundBefore = test::pixelsNear(all, classColor(2));
        QVERIFY(test::pixelsNear(all, classColor(6)) > 0);

        view.setClassVisible(6, false);
        QVERIFY(!view.isClassVisible(6));
        QVERIFY(view.isClassVisible(2));
        QVERIFY(view.renderSettings().hiddenClasses.test(6));
        const QImage hidden = view.renderImage(kImageSize);
        const double hiddenCoverage = test::coverage(hidden, test::viewBackground());
        QCOMPARE(test::pixelsNear(hidden, classColor(6), 60), 0);
        // The building half is gone, the ground half stays as it was.
        QVERIFY2(hiddenCoverage < allCoverage * 0.7 && hiddenCoverage > allCoverage * 0.3,
                 qPrintable(QStringLiteral("%1 -> %2").arg(allCoverage).arg(hiddenCoverage)));
        QVERIFY2(test::pixelsNear(hidden, classColor(2)) >= groundBefore * 95 / 100,
                 qPrintable(QStringLiteral("ground %1 -> %2")
                                .arg(groundBefore)
                                .arg(test::pixelsNear(hidden, classColor(2)))));

        // Hidden in every colour mode, not only by class: the coverage is the class's.
        settings = view.renderSettings();
        settings.color = ColorMode::Height;
        const QImage heightHidden = render(view, settings);
        QVERIFY(std::abs(test::coverage(heightHidden, test::viewBackground()) - hiddenCoverage) <
                0.01);

        // Shown again: the first image, pixel for pixel.
        view.setClassVisible(6, true);
        settings = view.renderSettings();
        settings.color = ColorMode::Classification;
        QCOMPARE(render(view, settings), all);
    }

    void returnNumberAndGpsTimeModesColourByTheirFields() {
        CloudView view;
        view.setHierarchy(m_hierarchy);
        view.setStandardView(StandardView::Top);
        const QImage height =
            render(view, plainSettings(RenderMode::ComputePoints, ColorMode::Height));
        const QImage returns =
            render(view, plainSettings(RenderMode::ComputePoints, ColorMode::ReturnNumber));
        const QImage gps =
            render(view, plainSettings(RenderMode::ComputePoints, ColorMode::GpsTime));
        QVERIFY(returns != height);
        QVERIFY(gps != height);
        QVERIFY(gps != returns);
        // Rows of returns 1 to 4: the four colours of color.glsl's returnColor, each on about a
        // quarter of the drawn pixels.
        const int covered =
            static_cast<int>(test::coverage(returns, test::viewBackground()) * 400 * 400);
        const QColor returnColors[] = {QColor(255, 199, 51), QColor(51, 204, 115),
                                       QColor(64, 115, 255), QColor(217, 77, 217)};
        for (const QColor& color : returnColors) {
            const int pixels = test::pixelsNear(returns, color);
            QVERIFY2(
                pixels > covered / 8,
                qPrintable(
                    QStringLiteral("%1: %2 of %3").arg(color.name()).arg(pixels).arg(covered)));
        }
        // GPS time grows along x: the ramp's dark end on the left, its bright end on the right
        // (the cloud's GPS times are 4e8 + 0 .. 390 s: as floats relative to a base they keep
        // their steps).
        const QImage rgb = gps.convertToFormat(QImage::Format_RGB32);
        const auto brightness = [&](int x) {
            const QRgb p = rgb.pixel(x, rgb.height() / 2);
            return qRed(p) + qGreen(p) + qBlue(p);
        };
        int left = 0, right = rgb.width() - 1;
        while (left < right && test::pixelsNear(rgb.copy(left, rgb.height() / 2, 1, 1),
                                                test::viewBackground(), 24) == 1) {
            ++left;
        }
        while (right > left && test::pixelsNear(rgb.copy(right, rgb.height() / 2, 1, 1),
                                                test::viewBackground(), 24) == 1) {
            --right;
        }
        QVERIFY2(right - left > 100, qPrintable(QStringLiteral("%1 .. %2").arg(left).arg(right)));
        QVERIFY2(
            brightness(right - 2) > brightness(left + 2) + 200,
            qPrintable(
                QStringLiteral("%1 vs %2").arg(brightness(left + 2)).arg(brightness(right - 2))));
    }

    void cloudsWithoutLasFieldsFallBackToHeight() {
        // A PLY has no LAS column.
        QTemporaryDir dir;
        const QString path = dir.filePath(QStringLiteral("plain.ply"));
        {
            QFile file(path);
            QVERIFY(file.open(QIODevice::WriteOnly | QIODevice::Text));
            QTextStream out(&file);
            out << "ply\nformat ascii 1.0\nelement vertex 100\nproperty float x\nproperty float "
                   "y\nproperty float z\nend_header\n";
            for (int i = 0; i < 100; ++i) {
                out << i % 10 << ' ' << i / 10 << ' ' << (i % 10) * 0.5 << '\n';
            }
        }
        const auto plain = test::buildHierarchy(path, BuildOptions{});
        CloudView view;
        view.setHierarchy(plain);
        view.setStandardView(StandardView::Top);
        const QImage height =
            render(view, plainSettings(RenderMode::ComputePoints, ColorMode::Height));
        for (const ColorMode mode :
             {ColorMode::Classification, ColorMode::ReturnNumber, ColorMode::GpsTime}) {
            QCOMPARE(render(view, plainSettings(RenderMode::ComputePoints, mode)), height);
        }
    }

    void pickedPointCarriesItsLasFields() {
        CloudView view;
        view.setRenderSettings(plainSettings(RenderMode::ComputePoints, ColorMode::Classification));
        view.setHierarchy(m_hierarchy);
        view.setStandardView(StandardView::Top);
        view.resize(400, 400);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view));
        // The right half of the grid is the building class; its GPS times are 4e8 + 200..390.
        std::optional<PickedPoint> picked;
        QTRY_VERIFY_WITH_TIMEOUT(
            (picked = view.pickCloudPoint(QPoint(view.width() * 3 / 4, view.height() / 2))),
            30'000);
        QVERIFY(picked->hasLas);
        QCOMPARE(int(picked->classification), 6);
        QVERIFY(picked->returnNumber >= 1 && picked->returnNumber <= 4);
        QCOMPARE(int(picked->numberOfReturns), 4);
        QVERIFY(picked->hasGpsTime);
        const double expectedGps = 4e8 + 10.0 * std::round(picked->source.x - 300000.0);
        QCOMPARE(picked->gpsTime, expectedGps);
        QCOMPARE(int(picked->returnNumber), int(std::lround(picked->source.y - 5000000.0)) % 4 + 1);
    }
};

QTEST_MAIN(tst_ClassificationGL)
#include "tst_classification_gl.moc"
