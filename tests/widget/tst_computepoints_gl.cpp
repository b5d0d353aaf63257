// RenderMode::ComputePoints under a real GL context (Xvfb + Mesa llvmpipe, OpenGL 4.5 core):
// the compute rasterizer draws what GL_POINTS draws (silhouette, colours, occlusion, depth for
// picking), and falls back to GL_POINTS where compute is unavailable. Checked by pixel
// statistics of renderImage() and grabFramebuffer() from fixed cameras.
#include "cloud_view.hpp"
#include "compute_rasterizer.hpp"
#include "points/cube_transform.hpp"
#include "sort/morton_sorter.hpp"
#include "widget_test_support.hpp"

#include <QOpenGLContext>
#include <QtTest>
#include <array>
#include <cmath>

using namespace omicron;

namespace {

RenderSettings plainSettings(RenderMode mode) {
    RenderSettings settings;
    settings.mode = mode;
    settings.showAxes = false;
    settings.showBoundingBox = false;
    settings.showCutBoundary = false;
    return settings;
}

bool covered(QRgb pixel, QRgb background) {
    return std::abs(qRed(pixel) - qRed(background)) + std::abs(qGreen(pixel) - qGreen(background)) +
               std::abs(qBlue(pixel) - qBlue(background)) >
           24;
}

struct ImageComparison {
    double coverageA = 0.0;
    double coverageB = 0.0;
    double coverageMismatch = 0.0; // pixels covered in one image only, over A's covered pixels
    std::array<double, 3> meanA{}; // mean RGB of the covered pixels
    std::array<double, 3> meanB{};
    double maxMeanDifference() const {
        double worst = 0.0;
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(meanA[c] - meanB[c]));
        }
        return worst;
    }
    QString describe() const {
        return QString("coverage %1 vs %2, mismatch %3, mean rgb (%4 %5 %6) vs (%7 %8 %9)")
            .arg(coverageA)
            .arg(coverageB)
            .arg(coverageMismatch)
            .arg(meanA[0])
            .arg(meanA[1])
            .arg(meanA[2])
            .arg(meanB[0])
            .arg(meanB[1])
            .arg(meanB[2]);
    }
};

ImageComparison compareImages(const QImage& a, const QImage& b) {
    const QImage rgbA = a.convertToFormat(QImage::Format_RGB32);
    const QImage rgbB = b.convertToFormat(QImage::Format_RGB32);
    const QRgb background = test::viewBackground().rgb();
    std::size_t coveredA = 0, coveredB = 0, mismatched = 0;
    std::array<double, 3> sumA{}, sumB{};
    for (int y = 0; y < rgbA.height(); ++y) {
        const auto* lineA = reinterpret_cast<const QRgb*>(rgbA.constScanLine(y));
        const auto* lineB = reinterpret_cast<const QRgb*>(rgbB.constScanLine(y));
        for (int x = 0; x < rgbA.width(); ++x) {
            const bool inA = covered(lineA[x], background);
            const bool inB = covered(lineB[x], background);
            mismatched += inA != inB ? 1 : 0;
            if (inA) {
                ++coveredA;
                sumA[0] += qRed(lineA[x]);
                sumA[1] += qGreen(lineA[x]);
                sumA[2] += qBlue(lineA[x]);
            }
            if (inB) {
                ++coveredB;
                sumB[0] += qRed(lineB[x]);
                sumB[1] += qGreen(lineB[x]);
                sumB[2] += qBlue(lineB[x]);
            }
        }
    }
    ImageComparison result;
    const double pixels = std::max(1, rgbA.width() * rgbA.height());
    result.coverageA = static_cast<double>(coveredA) / pixels;
    result.coverageB = static_cast<double>(coveredB) / pixels;
    result.coverageMismatch = static_cast<double>(mismatched) / std::max<double>(1.0, coveredA);
    for (int c = 0; c < 3; ++c) {
        result.meanA[c] = sumA[c] / std::max<double>(1.0, coveredA);
        result.meanB[c] = sumB[c] / std::max<double>(1.0, coveredB);
    }
    return result;
}

// Two square layers of points seen from the top: a small red one at z = 0.7 (near the camera)
// over a larger blue one at z = 0.3, in the order given.
PreviewSample twoLayers(bool nearFirst) {
    PreviewSample near, far;
    for (int i = 0; i < 10; ++i) {
        for (int j = 0; j < 10; ++j) {
            near.positions.emplace_back(0.4 + 0.2 * i / 9.0, 0.4 + 0.2 * j / 9.0, 0.7);
            near.colors.emplace_back(230, 30, 30);
        }
    }
    for (int i = 0; i < 20; ++i) {
        for (int j = 0; j < 20; ++j) {
            far.positions.emplace_back(0.2 + 0.6 * i / 19.0, 0.2 + 0.6 * j / 19.0, 0.3);
            far.colors.emplace_back(30, 30, 230);
        }
    }
    PreviewSample& first = nearFirst ? near : far;
    const PreviewSample& second = nearFirst ? far : near;
    first.positions.insert(first.positions.end(), second.positions.begin(), second.positions.end());
    first.colors.insert(first.colors.end(), second.colors.begin(), second.colors.end());
    first.pointsSeen = first.positions.size();
    return first;
}

ViewCamera topCamera() {
    ViewCamera camera;
    camera.setSceneBox(glm::dvec3(0.0), glm::dvec3(1.0));
    camera.setStandardView(StandardView::Top);
    return camera;
}

bool isRed(QColor c) {
    return c.red() > 150 && c.blue() < 100;
}
bool isBlue(QColor c) {
    return c.blue() > 150 && c.red() < 100;
}

} // namespace

class tst_ComputePointsGL : public QObject {
    Q_OBJECT

    // Where the context offers OpenGL 4.3 the compute path must be on; below, the test that
    // needs it is skipped (the fallback test covers that case).
    static bool requireCompute(CloudView& view) {
        if (view.computePointsAvailable()) {
            return true;
        }
        const QSurfaceFormat format = view.context()->format();
        return format.version() < qMakePair(4, 3);
    }

private slots:
    void silhouetteMatchesPointsMode_data() {
        QTest::addColumn<QString>("file");
        QTest::addColumn<double>("minCoverage");
        QTest::addColumn<double>("maxCoverage");
        QTest::newRow("bunny") << "bunny.ply" << 0.10 << 0.30;
        QTest::newRow("lion") << "lion.ply" << 0.05 << 0.60;
    }

    void silhouetteMatchesPointsMode() {
        QFETCH(QString, file);
        QFETCH(double, minCoverage);
        QFETCH(double, maxCoverage);
        const QString path = test::sharedDataFile(file.toUtf8().constData());
        if (path.isEmpty()) {
            QSKIP(qPrintable("../shared/data/" + file + " is absent"));
        }
        CloudView view;
        view.setRenderSettings(plainSettings(RenderMode::Points));
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        const QImage points = view.renderImage(QSize(400, 400));
        QVERIFY2(!points.isNull(), qPrintable(view.glErrorString()));
        const std::size_t pointsDrawn = view.lastFrameStats().pointsDrawn;
        view.setRenderSettings(plainSettings(RenderMode::ComputePoints));
        const QImage compute = view.renderImage(QSize(400, 400));
        if (!requireCompute(view)) {
            QFAIL("OpenGL 4.3 context without the compute point rasterizer");
        }
        if (!view.computePointsAvailable()) {
            QSKIP("no OpenGL 4.3 in this context");
        }
        QCOMPARE(view.lastFrameStats().pointsDrawn, pointsDrawn);
        const ImageComparison comparison = compareImages(points, compute);
        QVERIFY2(comparison.coverageB > minCoverage && comparison.coverageB < maxCoverage,
                 qPrintable(comparison.describe()));
        // The same footprints: coverage within 2 %, at most 3 % of the pixels differ in
        // coverage (rounding at footprint edges), the same colours on average.
        QVERIFY2(std::abs(comparison.coverageB - comparison.coverageA) <
                     0.02 * comparison.coverageA,
                 qPrintable(comparison.describe()));
        QVERIFY2(comparison.coverageMismatch < 0.03, qPrintable(comparison.describe()));
        QVERIFY2(comparison.maxMeanDifference() < 4.0, qPrintable(comparison.describe()));
    }

    void everyColourModeDrawsLikePointsMode() {
        const QString path = test::sharedDataFile("lion.ply");
        if (path.isEmpty()) {
            QSKIP("../shared/data/lion.ply is absent");
        }
        CloudView view;
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        std::vector<std::array<double, 3>> means;
        for (ColorMode color : {ColorMode::Rgb, ColorMode::Normal, ColorMode::Height,
                                ColorMode::Intensity, ColorMode::Level, ColorMode::BuildAge}) {
            RenderSettings settings = plainSettings(RenderMode::Points);
            settings.color = color;
            view.setRenderSettings(settings);
            const QImage points = view.renderImage(QSize(320, 320));
            settings.mode = RenderMode::ComputePoints;
            view.setRenderSettings(settings);
            const QImage compute = view.renderImage(QSize(320, 320));
            QVERIFY2(!compute.isNull(), qPrintable(view.glErrorString()));
            if (!view.computePointsAvailable()) {
                QVERIFY(requireCompute(view));
                QSKIP("no OpenGL 4.3 in this context");
            }
            const ImageComparison comparison = compareImages(points, compute);
            const QString what =
                QString("colour mode %1: ").arg(static_cast<int>(color)) + comparison.describe();
            QVERIFY2(comparison.coverageB > 0.05, qPrintable(what));
            QVERIFY2(comparison.coverageMismatch < 0.03, qPrintable(what));
            QVERIFY2(comparison.maxMeanDifference() < 4.0, qPrintable(what));
            means.push_back(comparison.meanB);
        }
        // The modes colour differently (so the compute passes honour the mode): RGB, normal,
        // height, level and build age each differ from RGB. (The lion has no intensity:
        // that mode shows height, like the points mode.)
        for (std::size_t mode : {1u, 2u, 4u, 5u}) {
            double difference = 0.0;
            for (int c = 0; c < 3; ++c) {
                difference += std::abs(means[mode][c] - means[0][c]);
            }
            QVERIFY2(difference > 10.0, qPrintable(QString("mode %1 looks like RGB").arg(mode)));
        }
    }

    void nearPointHidesFarPoint_data() {
        QTest::addColumn<int>("mode");
        QTest::addColumn<bool>("nearFirst");
        QTest::newRow("compute, near drawn first") << int(RenderMode::ComputePoints) << true;
        QTest::newRow("compute, far drawn first") << int(RenderMode::ComputePoints) << false;
        QTest::newRow("points, near drawn first") << int(RenderMode::Points) << true;
        QTest::newRow("points, far drawn first") << int(RenderMode::Points) << false;
    }

    void nearPointHidesFarPoint() {
        QFETCH(int, mode);
        QFETCH(bool, nearFirst);
        CloudView view;
        view.setRenderSettings(plainSettings(static_cast<RenderMode>(mode)));
        view.setPreview(twoLayers(nearFirst), CubeTransform{});
        view.setCamera(topCamera());
        const QImage image = view.renderImage(QSize(240, 240));
        QVERIFY2(!image.isNull(), qPrintable(view.glErrorString()));
        QVERIFY(requireCompute(view));
        // The near layer covers the centre; the far one shows around it.
        QVERIFY2(isRed(image.pixelColor(120, 120)), qPrintable(image.pixelColor(120, 120).name()));
        int red = 0, blue = 0;
        for (int y = 0; y < image.height(); ++y) {
            for (int x = 0; x < image.width(); ++x) {
                red += isRed(image.pixelColor(x, y)) ? 1 : 0;
                blue += isBlue(image.pixelColor(x, y)) ? 1 : 0;
            }
        }
        QVERIFY2(red > 200 && blue > 3 * red,
                 qPrintable(QString("red %1 blue %2").arg(red).arg(blue)));
        // Within the near layer's square nothing blue shows through.
        for (int y = 112; y <= 128; ++y) {
            for (int x = 112; x <= 128; ++x) {
                QVERIFY2(!isBlue(image.pixelColor(x, y)),
                         qPrintable(QString("blue at %1,%2").arg(x).arg(y)));
            }
        }
    }

    // The resolve pass writes depth: picking (double-click pivot, zoom to cursor) finds the
    // near layer under the cursor in a shown view, as with GL points.
    void pickingSeesComputeDepth_data() {
        QTest::addColumn<int>("mode");
        QTest::newRow("compute") << int(RenderMode::ComputePoints);
        QTest::newRow("points") << int(RenderMode::Points);
    }

    void pickingSeesComputeDepth() {
        QFETCH(int, mode);
        CloudView view;
        view.setAttribute(Qt::WA_DontShowOnScreen);
        view.resize(240, 240);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view) || view.isVisible());
        view.setRenderSettings(plainSettings(static_cast<RenderMode>(mode)));
        view.setPreview(twoLayers(false), CubeTransform{});
        view.setCamera(topCamera());
        const QImage frame = view.grabFramebuffer();
        QVERIFY2(!frame.isNull(), qPrintable(view.glErrorString()));
        QVERIFY(requireCompute(view));
        const auto picked = view.pickPoint(QPoint(120, 120));
        QVERIFY(picked.has_value());
        QVERIFY2(std::abs(picked->z() - 0.7f) < 0.02f, qPrintable(QString::number(picked->z())));
        QVERIFY(!view.pickPoint(QPoint(3, 3)).has_value()); // empty corner
    }

    // The per-pixel images follow the frame size (made again when it changes).
    void followsTheFrameSize() {
        const QString path = test::sharedDataFile("bunny.ply");
        if (path.isEmpty()) {
            QSKIP("../shared/data/bunny.ply is absent");
        }
        CloudView view;
        view.setRenderSettings(plainSettings(RenderMode::ComputePoints));
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        double previous = -1.0;
        for (const QSize size : {QSize(200, 160), QSize(480, 300), QSize(200, 160)}) {
            const QImage image = view.renderImage(size);
            QCOMPARE(image.size(), size);
            const double coverage = test::coverage(image, test::viewBackground());
            QVERIFY2(coverage > 0.05, qPrintable(QString::number(coverage)));
            if (size == QSize(200, 160) && previous >= 0.0) {
                QCOMPARE(coverage, previous); // the same size again: the same image
            }
            if (size == QSize(200, 160)) {
                previous = coverage;
            }
        }
    }

    // Without compute shaders (forced here as a 3.3 driver would), ComputePoints draws exactly
    // what Points draws and reports no error.
    void fallsBackToGlPointsWithoutCompute() {
        const QString path = test::sharedDataFile("bunny.ply");
        if (path.isEmpty()) {
            QSKIP("../shared/data/bunny.ply is absent");
        }
        qputenv(ComputeRasterizer::kDisableEnvironmentVariable, "1");
        CloudView view;
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        view.setRenderSettings(plainSettings(RenderMode::Points));
        const QImage points = view.renderImage(QSize(300, 300));
        view.setRenderSettings(plainSettings(RenderMode::ComputePoints));
        const QImage fallback = view.renderImage(QSize(300, 300));
        qunsetenv(ComputeRasterizer::kDisableEnvironmentVariable);
        QVERIFY2(!fallback.isNull(), qPrintable(view.glErrorString()));
        QVERIFY(!view.computePointsAvailable());
        QVERIFY(view.glErrorString().isEmpty());
        QVERIFY(test::coverage(fallback, test::viewBackground()) > 0.05);
        QVERIFY(view.lastFrameStats().pointsDrawn > 0);
        QVERIFY(fallback == points);

        // The variable is read when a context starts: a new view computes again.
        CloudView computing;
        computing.setRenderSettings(plainSettings(RenderMode::ComputePoints));
        QVERIFY(!computing.renderImage(QSize(64, 64)).isNull());
        QVERIFY(requireCompute(computing));
    }
};

QTEST_MAIN(tst_ComputePointsGL)
#include "tst_computepoints_gl.moc"
