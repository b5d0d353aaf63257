// CloudView under a real GL context (Xvfb + Mesa llvmpipe in CI): what it draws, checked by
// pixel statistics of renderImage() from fixed cameras.
#include "build/hierarchy_builder.hpp"
#include "cloud_view.hpp"
#include "formats/omh_writer.hpp"
#include "io/las/las_writer.hpp"
#include "io/point_reader.hpp"
#include "pipeline/build_pipeline.hpp"
#include "scale_bar.hpp"
#include "sort/morton_sorter.hpp"
#include "widget_test_support.hpp"

#include <QElapsedTimer>
#include <QFile>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTextStream>
#include <QtTest>
#include <cmath>

using namespace omicron;

namespace {

RenderSettings plainSettings() {
    RenderSettings settings;
    settings.showAxes = false;
    settings.showBoundingBox = false;
    settings.showCutBoundary = false;
    settings.showScaleBar = false;
    settings.showNorthArrow = false;
    return settings;
}

// A 20 x 20 grid of points 1 unit apart at x = 500000 + i, y = 4000000 + j (georeferenced
// magnitudes), z = 100 + zPerColumn * i, coloured (10 i, 10 j, 200): an ASCII PLY at `path`.
void writeGrid(const QString& path, double zPerColumn) {
    QFile file(path);
    QVERIFY(file.open(QIODevice::WriteOnly | QIODevice::Text));
    QTextStream out(&file);
    out << "ply\nformat ascii 1.0\nelement vertex 400\nproperty double x\n"
           "property double y\nproperty double z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nend_header\n";
    out.setRealNumberPrecision(12);
    for (int j = 0; j < 20; ++j) {
        for (int i = 0; i < 20; ++i) {
            out << 500000.0 + i << ' ' << 4000000.0 + j << ' ' << 100.0 + zPerColumn * i << ' '
                << 10 * i << ' ' << 10 * j << " 200\n";
        }
    }
}

// The grid built (its file is gone once the points are in memory).
std::shared_ptr<const Hierarchy> gridHierarchy(double zPerColumn) {
    QTemporaryDir dir;
    const QString path = dir.filePath(QStringLiteral("grid.ply"));
    writeGrid(path, zPerColumn);
    return test::buildHierarchy(path, BuildOptions{});
}

// `view` shown at 400 x 400 from above, drawing `hierarchy` with plain settings.
void showFromAbove(CloudView& view, std::shared_ptr<const Hierarchy> hierarchy) {
    view.setRenderSettings(plainSettings());
    view.setHierarchy(std::move(hierarchy));
    view.setStandardView(StandardView::Top);
    view.resize(400, 400);
    view.show();
    QVERIFY(QTest::qWaitForWindowExposed(&view));
}

// Where the view draws the source point `p` of `hierarchy` (widget coordinates).
QPoint pixelOf(const CloudView& view, const Hierarchy& hierarchy, const glm::dvec3& p) {
    const glm::dvec3 unit(hierarchy.cloud().cube().toUnit(p));
    const ViewCamera camera = view.camera();
    const glm::dvec4 clip =
        camera.projectionMatrix(static_cast<double>(view.width()) / view.height()) *
        camera.viewMatrix() * glm::dvec4(unit, 1.0);
    const glm::dvec3 ndc = glm::dvec3(clip) / clip.w;
    return QPoint(static_cast<int>((ndc.x * 0.5 + 0.5) * view.width()),
                  static_cast<int>((0.5 - ndc.y * 0.5) * view.height()));
}

PreviewSample spherePreview(std::size_t count) {
    PreviewSample preview;
    for (std::size_t i = 0; i < count; ++i) {
        // A Fibonacci sphere: evenly spread points of radius 0.4 around the cube's centre.
        const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(count);
        const double ring = std::sqrt(1.0 - z * z);
        const double angle = static_cast<double>(i) * 2.399963229728653;
        preview.positions.emplace_back(0.5 + 0.4 * ring * std::cos(angle),
                                       0.5 + 0.4 * ring * std::sin(angle), 0.5 + 0.4 * z);
        preview.colors.emplace_back(220, 40, 40);
    }
    preview.pointsSeen = count;
    return preview;
}

std::shared_ptr<const Hierarchy> generatedHierarchy(std::uint64_t points) {
    BuildPipeline pipeline; // the hierarchy outlives it (shared)
    PipelineOptions options;
    options.build.maxLevel = 7;
    pipeline.runGeneratedScene(points, 1, options);
    return pipeline.hierarchy();
}

} // namespace

class tst_CloudViewGL : public QObject {
    Q_OBJECT
private slots:
    void emptyViewDrawsOnlyTheBackground() {
        CloudView view;
        view.setRenderSettings(plainSettings());
        const QImage image = view.renderImage(QSize(200, 150));
        QVERIFY2(!image.isNull(), qPrintable(view.glErrorString()));
        QCOMPARE(image.size(), QSize(200, 150));
        QCOMPARE(test::coverage(image, test::viewBackground()), 0.0);
    }

    void previewIsDrawnBeforeAnyHierarchy() {
        CloudView view;
        view.setRenderSettings(plainSettings());
        view.setPreview(spherePreview(20000), CubeTransform{});
        const QImage image = view.renderImage(QSize(320, 240));
        QVERIFY2(!image.isNull(), qPrintable(view.glErrorString()));
        const double covered = test::coverage(image, test::viewBackground());
        // Fitting frames the box's bounding sphere: this sphere's disc spans about half the
        // frame height, pi * (0.25 * 240)^2 / (320 * 240) = 0.147 of the pixels.
        QVERIFY2(covered > 0.12 && covered < 0.2, qPrintable(QString::number(covered)));
        QVERIFY(view.lastFrameStats().showingPreview);
        QCOMPARE(view.lastFrameStats().pointsDrawn, std::size_t{20000});
        // The centre is red, the corner is background.
        const QColor centre = image.pixelColor(160, 120);
        QVERIFY2(centre.red() > 150 && centre.green() < 100, qPrintable(centre.name()));
        QCOMPARE(image.pixelColor(2, 2).rgb(), test::viewBackground().rgb());
    }

    void bunnyRendersWithItsSilhouette() {
        const QString path = test::sharedDataFile("bunny.ply");
        if (path.isEmpty()) {
            QSKIP("../shared/data/bunny.ply is absent");
        }
        CloudView view;
        view.setRenderSettings(plainSettings());
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        const QImage image = view.renderImage(QSize(400, 400));
        QVERIFY2(!image.isNull(), qPrintable(view.glErrorString()));
        const double covered = test::coverage(image, test::viewBackground());
        image.save("/tmp/bunny_front.png");
        QVERIFY2(covered > 0.10 && covered < 0.3, qPrintable(QString::number(covered)));
        QVERIFY(!view.lastFrameStats().showingPreview);
        QVERIFY(view.lastFrameStats().pointsDrawn > 0);
    }

    // Eye-dome lighting darkens pixels behind their neighbours and never adds or removes one:
    // the bunny (no colours) in every render mode, off against on; Auto shades it and not the
    // coloured lion.
    void eyeDomeLightingShadesAnUncolouredCloudAndKeepsItsCoverage() {
        const QString bunny = test::sharedDataFile("bunny.ply");
        const QString lion = test::sharedDataFile("lion.ply");
        if (bunny.isEmpty() || lion.isEmpty()) {
            QSKIP("../shared/data/bunny.ply or lion.ply is absent");
        }
        CloudView view;
        view.setHierarchy(test::buildHierarchy(bunny, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        for (const RenderMode mode :
             {RenderMode::ComputePoints, RenderMode::Points, RenderMode::Splats}) {
            RenderSettings settings = plainSettings();
            settings.mode = mode;
            settings.edl = EdlMode::Off;
            view.setRenderSettings(settings);
            const QImage plain = view.renderImage(QSize(400, 400));
            QVERIFY(!view.lastFrameStats().eyeDomeLighting);
            settings.edl = EdlMode::On;
            view.setRenderSettings(settings);
            const QImage shaded = view.renderImage(QSize(400, 400));
            QVERIFY(view.lastFrameStats().eyeDomeLighting);
            // The same pixels drawn (the background is cleared to one exact colour), darker
            // where it changed, and changed on a good part of the cloud.
            const QRgb background = plain.pixel(0, 0);
            int drawn = 0, sameCoverage = 0, changed = 0, darker = 0;
            for (int y = 0; y < plain.height(); ++y) {
                for (int x = 0; x < plain.width(); ++x) {
                    const QRgb a = plain.pixel(x, y), b = shaded.pixel(x, y);
                    drawn += a != background ? 1 : 0;
                    sameCoverage += (a != background) == (b != background) ? 1 : 0;
                    if (a != b) {
                        ++changed;
                        darker += qGray(b) <= qGray(a) ? 1 : 0;
                    }
                }
            }
            const QString trace = QStringLiteral("mode %1: %2 drawn, %3 changed, %4 darker")
                                      .arg(static_cast<int>(mode))
                                      .arg(drawn)
                                      .arg(changed)
                                      .arg(darker);
            QCOMPARE(shaded.pixel(0, 0), background);
            QVERIFY2(drawn > 400 * 400 / 20, qPrintable(trace));
            QVERIFY2(sameCoverage == 400 * 400, qPrintable(trace));
            QVERIFY2(changed > drawn / 10, qPrintable(trace));
            QVERIFY2(darker >= changed * 99 / 100, qPrintable(trace));
        }
        RenderSettings automatic = plainSettings();
        QCOMPARE(automatic.edl, EdlMode::Auto);
        view.setRenderSettings(automatic);
        QVERIFY(!view.renderImage(QSize(200, 200)).isNull());
        QVERIFY(view.lastFrameStats().eyeDomeLighting); // no colours: shaded
        view.setHierarchy(test::buildHierarchy(lion, BuildOptions{}));
        QVERIFY(!view.renderImage(QSize(200, 200)).isNull());
        QVERIFY(!view.lastFrameStats().eyeDomeLighting); // colours of its own: as they are
    }

    // A pick at the pixel where a known point is drawn returns that point: a 20 x 20 grid of
    // coloured points 1 m apart with a georeferenced offset, seen from above; over empty
    // space, nothing. Hovering emits the same point.
    void aPickAtAKnownPixelReturnsTheKnownPoint() {
        const auto hierarchy = gridHierarchy(0.0);
        CloudView view;
        showFromAbove(view, hierarchy);
        QVERIFY(!QTest::currentTestFailed());
        QTRY_VERIFY(view.lastFrameStats().pointsDrawn == 400);
        for (const auto& [i, j] : {std::pair{7, 11}, std::pair{0, 0}, std::pair{19, 3}}) {
            const auto picked = view.pickCloudPoint(
                pixelOf(view, *hierarchy, glm::dvec3(500000.0 + i, 4000000.0 + j, 100.0)));
            QVERIFY2(picked.has_value(),
                     qPrintable(QStringLiteral("grid point %1 %2").arg(i).arg(j)));
            QVERIFY2(std::abs(picked->source.x - (500000.0 + i)) < 1e-3 &&
                         std::abs(picked->source.y - (4000000.0 + j)) < 1e-3 &&
                         std::abs(picked->source.z - 100.0) < 1e-3,
                     qPrintable(QStringLiteral("grid point %1 %2 picked as %3 %4 %5")
                                    .arg(i)
                                    .arg(j)
                                    .arg(picked->source.x, 0, 'f', 3)
                                    .arg(picked->source.y, 0, 'f', 3)
                                    .arg(picked->source.z, 0, 'f', 3)));
            QVERIFY(picked->hasColor);
            QCOMPARE(int(picked->color.r), 10 * i);
            QCOMPARE(int(picked->color.g), 10 * j);
            QVERIFY(picked->level >= 0);
        }
        QVERIFY(!view.pickCloudPoint(QPoint(2, 2)).has_value()); // the corner: background
        QSignalSpy hovered(&view, &CloudView::pointHovered);
        view.setHoverPicking(true);
        QTest::mouseMove(&view, pixelOf(view, *hierarchy, glm::dvec3(500007.0, 4000011.0, 100.0)));
        QTRY_COMPARE(hovered.count(), 1);
        const auto point = hovered.first().at(0).value<PickedPoint>();
        QVERIFY(std::abs(point.source.x - 500007.0) < 1e-3);
    }

    // The measure tool: clicks on drawn points of the grid (z rising by 0.5 per column) give
    // the distance, height difference, polyline length and horizontal area of those points.
    void measurementsBetweenPickedPointsAreTheirGeometry() {
        const auto hierarchy = gridHierarchy(0.5);
        CloudView view;
        showFromAbove(view, hierarchy);
        QVERIFY(!QTest::currentTestFailed());
        QTRY_VERIFY(view.lastFrameStats().pointsDrawn == 400);
        const auto grid = [](int i, int j) {
            return glm::dvec3(500000.0 + i, 4000000.0 + j, 100.0 + 0.5 * i);
        };
        const auto click = [&](int i, int j) {
            QTest::mouseClick(&view, Qt::LeftButton, {}, pixelOf(view, *hierarchy, grid(i, j)));
        };
        // Positions are float in the unit cube: a 19-unit cube keeps them to about 2e-6.
        constexpr double kTolerance = 1e-4;
        QSignalSpy changed(&view, &CloudView::measurementsChanged);
        click(0, 0); // no tool: navigation only
        QVERIFY(view.measurements().empty());

        view.setMeasureTool(MeasureKind::Distance);
        click(0, 0);
        QVERIFY(view.measurementInProgress() != nullptr);
        click(5, 12);
        QCOMPARE(view.measurements().size(), std::size_t{1});
        QVERIFY(std::abs(view.measurements()[0].value() - glm::length(grid(5, 12) - grid(0, 0))) <
                1e-6);

        view.setMeasureTool(MeasureKind::Height);
        click(2, 3);
        click(6, 3);
        QCOMPARE(view.measurements().size(), std::size_t{2});
        QVERIFY(std::abs(view.measurements()[1].value() - 2.0) < kTolerance);

        view.setMeasureTool(MeasureKind::Polyline);
        click(0, 0);
        click(3, 4);
        click(3, 10);
        QCOMPARE(view.measurements().size(), std::size_t{2}); // open until finished
        QTest::keyClick(&view, Qt::Key_Return);
        QCOMPARE(view.measurements().size(), std::size_t{3});
        const double polyline =
            glm::length(grid(3, 4) - grid(0, 0)) + glm::length(grid(3, 10) - grid(3, 4));
        QVERIFY(std::abs(view.measurements()[2].value() - polyline) < kTolerance);

        view.setMeasureTool(MeasureKind::Area);
        click(0, 0);
        click(10, 0);
        click(10, 10);
        click(0, 10);
        view.finishMeasurement();
        QCOMPARE(view.measurements().size(), std::size_t{4});
        QVERIFY2(std::abs(view.measurements()[3].value() - 100.0) < kTolerance,
                 qPrintable(
                     view.measurements()[3].valueText() +
                     QStringLiteral(" from %1 points").arg(view.measurements()[3].points.size())));
        QVERIFY(view.measurements()[3].valueText().startsWith(QStringLiteral("100.000")));

        // Over empty space a click adds nothing; Escape drops an unfinished one.
        QVERIFY(!view.addMeasurePoint(QPoint(2, 2)));
        click(1, 1);
        QVERIFY(view.measurementInProgress() != nullptr);
        QTest::keyClick(&view, Qt::Key_Escape);
        QVERIFY(view.measurementInProgress() == nullptr);
        view.removeMeasurement(0);
        QCOMPARE(view.measurements().size(), std::size_t{3});
        QVERIFY(changed.count() >= 10);
        // The lines and labels are drawn: the frame changes where they are.
        const QImage with = view.grabFramebuffer();
        view.clearMeasurements();
        const QImage without = view.grabFramebuffer();
        QVERIFY(with != without);
    }

    // The clip box: in every render mode, the grid points outside it are not drawn (no depth
    // there to pick) and those inside are; the front culls cells wholly outside.
    void theClipBoxDrawsOnlyThePointsInside() {
        QTemporaryDir dir;
        const QString path = dir.filePath(QStringLiteral("grid.ply"));
        writeGrid(path, 0.0);
        const auto hierarchy = test::buildHierarchy(path, BuildOptions{});
        CloudView view;
        view.setHierarchy(hierarchy);
        view.setStandardView(StandardView::Top);
        view.resize(400, 400);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view));
        for (const RenderMode mode :
             {RenderMode::ComputePoints, RenderMode::Points, RenderMode::Splats}) {
            RenderSettings settings = plainSettings();
            settings.mode = mode;
            // Columns 0..9 (x up to 500009.5), turned by a quarter turn: its x along +y.
            settings.clip =
                ClipBox{{500004.75, 4000009.5, 100.0}, {10.0, 4.75, 1.0}, std::acos(-1.0) / 2.0};
            view.setRenderSettings(settings);
            view.update();
            QTRY_VERIFY(view.lastFrameStats().pointsDrawn > 0);
            QTest::qWait(50);
            const QString trace = QStringLiteral("mode %1").arg(static_cast<int>(mode));
            for (int j : {2, 10, 17}) {
                const auto inside = view.pickCloudPoint(
                    pixelOf(view, *hierarchy, glm::dvec3(500003.0, 4000000.0 + j, 100.0)));
                QVERIFY2(inside && std::abs(inside->source.x - 500003.0) < 1e-3, qPrintable(trace));
                const auto outside = view.pickCloudPoint(
                    pixelOf(view, *hierarchy, glm::dvec3(500016.0, 4000000.0 + j, 100.0)));
                QVERIFY2(!outside || outside->source.x < 500010.0,
                         qPrintable(trace + QStringLiteral(": picked %1").arg(outside->source.x)));
            }
            QVERIFY2(view.lastFrameStats().pointsDrawn < 400, qPrintable(trace));
        }
    }

    // Orthographic projection keeps parallel edges parallel and equally long on screen: two
    // vertical edges of a cube (red at the corner nearest the iso view, green at the next
    // one), seen from the iso view, differ in screen length with perspective and not without.
    void orthographicKeepsParallelEdgesParallel() {
        QTemporaryDir dir;
        const QString path = dir.filePath(QStringLiteral("edges.ply"));
        {
            QFile file(path);
            QVERIFY(file.open(QIODevice::WriteOnly | QIODevice::Text));
            QTextStream out(&file);
            out << "ply\nformat ascii 1.0\nelement vertex 808\nproperty float x\n"
                   "property float y\nproperty float z\nproperty uchar red\n"
                   "property uchar green\nproperty uchar blue\nend_header\n";
            for (int i = 0; i <= 400; ++i) { // the two edges, and the cube's other corners
                out << "0 0 " << i / 400.0 << " 255 0 0\n";
                out << "1 0 " << i / 400.0 << " 0 255 0\n";
            }
            out << "1 1 0 0 0 255\n0 1 0 0 0 255\n1 1 1 0 0 255\n0 1 1 0 0 255\n"
                   "0 0 0.5 255 0 0\n1 0 0.5 0 255 0\n";
        }
        CloudView view;
        RenderSettings settings = plainSettings();
        settings.projectionThresholdPx = 1.0; // every point, at the deepest level
        settings.edl = EdlMode::Off;
        view.setRenderSettings(settings);
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Iso);
        const auto screenHeights = [&](const QImage& image) {
            int top[2] = {image.height(), image.height()}, bottom[2] = {-1, -1};
            for (int y = 0; y < image.height(); ++y) {
                for (int x = 0; x < image.width(); ++x) {
                    const QColor c = image.pixelColor(x, y);
                    const int edge = c.red() > 150 && c.green() < 80   ? 0
                                     : c.green() > 150 && c.red() < 80 ? 1
                                                                       : -1;
                    if (edge >= 0) {
                        top[edge] = std::min(top[edge], y);
                        bottom[edge] = std::max(bottom[edge], y);
                    }
                }
            }
            return std::pair{bottom[0] - top[0], bottom[1] - top[1]};
        };
        const auto [redPerspective, greenPerspective] =
            screenHeights(view.renderImage(QSize(400, 400)));
        QVERIFY(!view.orthographic());
        view.setOrthographic(true);
        QVERIFY(view.orthographic());
        const auto [redOrtho, greenOrtho] = screenHeights(view.renderImage(QSize(400, 400)));
        const QString trace = QStringLiteral("perspective %1 vs %2 px, orthographic %3 vs %4 px")
                                  .arg(redPerspective)
                                  .arg(greenPerspective)
                                  .arg(redOrtho)
                                  .arg(greenOrtho);
        QVERIFY2(redOrtho > 50 && greenOrtho > 50, qPrintable(trace));
        QVERIFY2(std::abs(redPerspective - greenPerspective) > 8, qPrintable(trace));
        QVERIFY2(std::abs(redOrtho - greenOrtho) <= 2, qPrintable(trace));
        // Picking works through the orthographic projection too (a shown view).
        CloudView shown;
        shown.setRenderSettings(settings);
        shown.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        shown.setStandardView(StandardView::Iso);
        shown.setOrthographic(true);
        shown.resize(400, 400);
        shown.show();
        QVERIFY(QTest::qWaitForWindowExposed(&shown));
        QTRY_VERIFY(shown.lastFrameStats().pointsDrawn > 0);
        std::optional<PickedPoint> picked;
        for (int y = 0; y < 400 && !picked; y += 2) {
            for (int x = 0; x < 400 && !picked; x += 2) {
                picked = shown.pickCloudPoint(QPoint(x, y));
            }
        }
        QVERIFY(picked.has_value());
        // A point of one of the edges or a corner of the cube, exactly.
        QVERIFY(std::abs(picked->source.x - std::round(picked->source.x)) < 1e-5);
    }

    // The scale bar (bottom right) and, for a georeferenced cloud, the north arrow (top right)
    // are painted over the frame and into screenshots; a cloud in local coordinates gets no
    // arrow.
    void scaleBarAndNorthArrowArePaintedWhereTheyBelong() {
        const ScaleBar bar = scaleBarFor(0.37, 200.0);
        QCOMPARE(bar.length, 50.0);
        QCOMPARE(bar.label, QStringLiteral("50"));
        QVERIFY(std::abs(bar.widthPx - 50.0 / 0.37) < 1e-9);
        QCOMPARE(scaleBarFor(0.0013, 100.0).label, QStringLiteral("0.1"));

        QTemporaryDir dir;
        const QString path = dir.filePath(QStringLiteral("grid.ply"));
        writeGrid(path, 0.0); // x = 500000 + i: georeferenced
        CloudView view;
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Top);
        const auto differs = [](const QImage& a, const QImage& b, const QRect& region) {
            int changed = 0;
            for (int y = region.top(); y <= region.bottom(); ++y) {
                for (int x = region.left(); x <= region.right(); ++x) {
                    changed += a.pixel(x, y) != b.pixel(x, y) ? 1 : 0;
                }
            }
            return changed;
        };
        const QRect bottomRight(300, 340, 100, 60), topRight(330, 0, 70, 80),
            middle(100, 100, 200, 200);
        RenderSettings settings = plainSettings();
        view.setRenderSettings(settings);
        const QImage none = view.renderImage(QSize(400, 400));
        settings.showScaleBar = true;
        view.setRenderSettings(settings);
        const QImage withBar = view.renderImage(QSize(400, 400));
        QVERIFY(differs(none, withBar, bottomRight) > 50);
        QCOMPARE(differs(none, withBar, topRight), 0);
        QCOMPARE(differs(none, withBar, middle), 0);
        settings.showScaleBar = false;
        settings.showNorthArrow = true;
        view.setRenderSettings(settings);
        const QImage withArrow = view.renderImage(QSize(400, 400));
        QVERIFY(differs(none, withArrow, topRight) > 30);
        QCOMPARE(differs(none, withArrow, bottomRight), 0);

        const QString bunny = test::sharedDataFile("bunny.ply");
        if (!bunny.isEmpty()) { // local coordinates: no arrow
            view.setHierarchy(test::buildHierarchy(bunny, BuildOptions{}));
            settings.showNorthArrow = false;
            view.setRenderSettings(settings);
            const QImage local = view.renderImage(QSize(400, 400));
            settings.showNorthArrow = true;
            view.setRenderSettings(settings);
            QCOMPARE(differs(local, view.renderImage(QSize(400, 400)), QRect(0, 0, 400, 400)), 0);
        }

        // Local coordinates in a file that names its coordinate system (a LASF_Projection
        // GeoKeyDirectory: projected, UTM 10N) get the arrow too; the same file without the
        // record does not.
        for (const bool withCrs : {false, true}) {
            const QString las =
                dir.filePath(withCrs ? QStringLiteral("crs.las") : QStringLiteral("local.las"));
            Bounds bounds;
            bounds.extend(glm::dvec3(0.0));
            bounds.extend(glm::dvec3(19.0, 19.0, 0.0));
            const CubeTransform cube = CubeTransform::fromBounds(bounds);
            PointBatch batch;
            for (int j = 0; j < 20; ++j) {
                for (int i = 0; i < 20; ++i) {
                    batch.positions.push_back(cube.toUnit(glm::dvec3(i, j, 0.0)));
                }
            }
            LasWriteOptions options;
            if (withCrs) {
                LasVariableLengthRecord keys;
                keys.userId = "LASF_Projection";
                keys.recordId = 34735;
                // Version 1.1.0, one key: ProjectedCSTypeGeoKey (3072) = 32610.
                for (const std::uint16_t value : {1, 1, 0, 1, 3072, 0, 1, 32610}) {
                    keys.payload.push_back(static_cast<std::uint8_t>(value & 0xFF));
                    keys.payload.push_back(static_cast<std::uint8_t>(value >> 8));
                }
                options.vlrs.push_back(keys);
            }
            writeLas(las.toStdString(), batch, cube, options);
            view.setHierarchy(test::buildHierarchy(las, BuildOptions{}));
            view.setStandardView(StandardView::Top);
            settings.showNorthArrow = false;
            view.setRenderSettings(settings);
            const QImage plain = view.renderImage(QSize(400, 400));
            settings.showNorthArrow = true;
            view.setRenderSettings(settings);
            const int arrowPixels = differs(plain, view.renderImage(QSize(400, 400)), topRight);
            if (withCrs) {
                QVERIFY2(arrowPixels > 30, "a cloud with a coordinate system gets the arrow");
            } else {
                QCOMPARE(arrowPixels, 0);
            }
        }
    }

    void lionRendersInColourAndAsSplats() {
        const QString path = test::sharedDataFile("lion.ply");
        if (path.isEmpty()) {
            QSKIP("../shared/data/lion.ply is absent");
        }
        CloudView view;
        RenderSettings settings = plainSettings();
        view.setRenderSettings(settings);
        view.setHierarchy(test::buildHierarchy(path, BuildOptions{}));
        view.setStandardView(StandardView::Front);
        const QImage points = view.renderImage(QSize(400, 400));
        points.save("/tmp/lion_points.png");
        settings.mode = RenderMode::Splats;
        view.setRenderSettings(settings);
        const QImage splats = view.renderImage(QSize(400, 400));
        splats.save("/tmp/lion_splats.png");
        const double pointCoverage = test::coverage(points, test::viewBackground());
        const double splatCoverage = test::coverage(splats, test::viewBackground());
        QVERIFY2(pointCoverage > 0.05, qPrintable(QString::number(pointCoverage)));
        QVERIFY2(std::abs(splatCoverage - pointCoverage) < 0.25 * pointCoverage,
                 qPrintable(QString("%1 vs %2").arg(splatCoverage).arg(pointCoverage)));
    }

    // A .omh beyond the memory budget is drawn with its points paged in on demand: a
    // screenshot waits for the nodes its front asks for, so it draws what the whole load
    // draws (framed by the node cells instead of the points: the coverage is close, not
    // equal); another view evicts what the first one held.
    void aPagedHierarchyDrawsLikeTheWholeLoadAndEvictsUnderItsBudget() {
        const QString source = test::sharedDataFile("lion.ply");
        if (source.isEmpty()) {
            QSKIP("../shared/data/lion.ply is absent");
        }
        QTemporaryDir dir;
        const std::string omh = dir.filePath("lion.omh").toStdString();
        {
            BuildPipeline builder;
            PipelineOptions options;
            builder.run(source.toStdString(), options);
            writeOmh(omh, *builder.hierarchy(),
                     omhBuildInfo(builder.hierarchyOptions(), builder.statistics()));
        }
        BuildPipeline whole;
        QVERIFY(!whole.run(omh, PipelineOptions{}).pagedPoints);
        CloudView wholeView;
        wholeView.setRenderSettings(plainSettings());
        wholeView.setHierarchy(whole.hierarchy());
        wholeView.setStandardView(StandardView::Front);
        const QImage wholeImage = wholeView.renderImage(QSize(400, 400));

        BuildPipeline paged;
        PipelineOptions budgeted;
        budgeted.memoryBudgetBytes = 256 * 1024; // a tenth of what the front draws
        QVERIFY(paged.run(omh, budgeted).pagedPoints);
        CloudView pagedView;
        pagedView.setRenderSettings(plainSettings());
        pagedView.setHierarchy(paged.hierarchy());
        pagedView.setStandardView(StandardView::Front);
        const QImage pagedImage = pagedView.renderImage(QSize(400, 400));
        pagedImage.save("/tmp/lion_paged.png");
        const FrameStats stats = pagedView.lastFrameStats();
        QVERIFY(stats.pagedPoints);
        QCOMPARE(stats.pendingLoads, std::uint64_t{0});
        QVERIFY(stats.pointsDrawn > 0);
        const double wholeCoverage = test::coverage(wholeImage, test::viewBackground());
        const double pagedCoverage = test::coverage(pagedImage, test::viewBackground());
        QVERIFY2(std::abs(pagedCoverage - wholeCoverage) < 0.15 * wholeCoverage,
                 qPrintable(QString("%1 vs %2").arg(pagedCoverage).arg(wholeCoverage)));

        NodeResidency& residency = *paged.hierarchy()->residency();
        const std::uint64_t loadsBefore = residency.stats().loads;
        pagedView.setStandardView(StandardView::Top);
        const QImage top = pagedView.renderImage(QSize(400, 400));
        QVERIFY(test::coverage(top, test::viewBackground()) > 0.02);
        const ResidencyStats after = residency.stats();
        QVERIFY2(after.evictions > 0, "the first view's nodes were not given back");
        QVERIFY(after.loads > loadsBefore);
        QCOMPARE(after.failedNodes, std::uint64_t{0});
        QCOMPARE(pagedView.lastFrameStats().pendingLoads, std::uint64_t{0});
    }

    // FrameStats carries the front's nodes per level; they add up to the front's size.
    void frontNodesPerLevelAddUpToTheFront() {
        const auto hierarchy = generatedHierarchy(60'000);
        CloudView view;
        view.setRenderSettings(plainSettings());
        view.setHierarchy(hierarchy);
        QVERIFY2(!view.renderImage(QSize(320, 240)).isNull(), qPrintable(view.glErrorString()));
        const FrameStats stats = view.lastFrameStats();
        QVERIFY(stats.frontNodes > 1);
        std::size_t sum = 0;
        int levelsUsed = 0;
        for (std::size_t level = 0; level < stats.frontNodesPerLevel.size(); ++level) {
            sum += stats.frontNodesPerLevel[level];
            levelsUsed += stats.frontNodesPerLevel[level] > 0 ? 1 : 0;
            if (level > static_cast<std::size_t>(hierarchy->maxLevel())) {
                QCOMPARE(stats.frontNodesPerLevel[level], std::size_t{0});
            }
        }
        QCOMPARE(sum, stats.frontNodes);
        QVERIFY(levelsUsed >= 1);
    }

    // setHighlightedNode draws the node's cell as a magenta box through the points, whatever
    // the overlay settings; clearing it restores the image.
    void highlightedNodeIsDrawnAsABox() {
        const auto hierarchy = generatedHierarchy(60'000);
        CloudView view;
        view.setRenderSettings(plainSettings());
        view.setHierarchy(hierarchy);
        view.setStandardView(StandardView::Iso);
        const QImage plain = view.renderImage(QSize(320, 240));
        QVERIFY2(!plain.isNull(), qPrintable(view.glErrorString()));
        QCOMPARE(test::magentaPixels(plain), 0);

        QVERIFY(hierarchy->nodeCount(1) > 0);
        const std::uint64_t code = hierarchy->node(1, 0).code;
        view.setHighlightedNode(1, code);
        QCOMPARE(view.highlightedNode(), std::optional<std::uint64_t>(code));
        const QImage highlighted = view.renderImage(QSize(320, 240));
        const int boxPixels = test::magentaPixels(highlighted);
        // Twelve edges of a cell an eighth of the cloud's cube: well over a hundred pixels.
        QVERIFY2(boxPixels > 100, qPrintable(QString::number(boxPixels)));
        int changed = 0;
        for (int y = 0; y < plain.height(); ++y) {
            for (int x = 0; x < plain.width(); ++x) {
                changed += plain.pixel(x, y) != highlighted.pixel(x, y) ? 1 : 0;
            }
        }
        QVERIFY(changed >= boxPixels);

        view.clearHighlightedNode();
        QVERIFY(!view.highlightedNode().has_value());
        QCOMPARE(test::magentaPixels(view.renderImage(QSize(320, 240))), 0);

        // A code that is not of the given level clears the highlight.
        view.setHighlightedNode(1, code);
        QTest::ignoreMessage(QtWarningMsg, QRegularExpression("not of level 3"));
        view.setHighlightedNode(3, code);
        QVERIFY(!view.highlightedNode().has_value());
    }

    // Frames are drawn on demand: the rate is measured over frames drawn back to back, and a
    // frame after a pause starts a new window instead of reporting the pause as a low rate.
    void framesPerSecondIgnoreIdlePauses() {
        CloudView view;
        view.resize(160, 120);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view));
        const auto drawFor = [&](qint64 ms) {
            QElapsedTimer clock;
            clock.start();
            while (clock.elapsed() < ms) {
                view.repaint();
                QCoreApplication::processEvents();
            }
        };
        drawFor(1300);
        const double drawing = view.lastFrameStats().fps;
        QVERIFY2(drawing > 2.0, qPrintable(QString::number(drawing)));
        QTest::qWait(2200); // idle: no frame
        view.repaint();
        QCOMPARE(view.lastFrameStats().fps, drawing);
        drawFor(1300);
        QVERIFY(view.lastFrameStats().fps > 2.0);
    }

    // The front insertion delay (leaf published -> first drawn) through a real build: every
    // leaf the builder logs after the view attached is counted exactly once over the frames,
    // each frame with its median below its maximum.
    void leafDrawDelayIsMeasuredWhileABuildRuns() {
        const test::SortedScene scene = test::sortGeneratedScene(150'000, 4);
        const auto& ranges = scene.ranges;
        QVERIFY(ranges.size() >= 8);

        BuildOptions options;
        options.maxLevel = 7;
        HierarchyBuilder builder(scene.cloud(), options);
        CloudView view;
        view.setRenderSettings(plainSettings());
        view.setHierarchy(builder.sharedHierarchy()); // before the first leaf is published
        ViewCamera camera; // the whole cube in view: every leaf gets drawn in the end
        camera.setSceneBox(glm::dvec3(0.0), glm::dvec3(1.0));
        camera.setStandardView(StandardView::Iso);
        view.setCamera(camera);

        std::size_t firstDrawn = 0;
        int framesWithLeaves = 0;
        bool delaysOrdered = true;
        const auto count = [&](const FrameStats& stats) {
            firstDrawn += stats.leavesFirstDrawn;
            framesWithLeaves += stats.leavesFirstDrawn > 0 ? 1 : 0;
            delaysOrdered = delaysOrdered && stats.leafDrawDelayMedianMs >= 0.0 &&
                            stats.leafDrawDelayMedianMs <= stats.leafDrawDelayMaxMs &&
                            (stats.leavesFirstDrawn > 0 || stats.leafDrawDelayMaxMs == 0.0);
        };
        // The shown (off-screen) view also paints on its own: those frames count too.
        connect(&view, &CloudView::frameRendered, this, count);
        const auto frame = [&] {
            QVERIFY2(!view.renderImage(QSize(200, 200)).isNull(), qPrintable(view.glErrorString()));
            count(view.lastFrameStats());
        };
        for (const auto& [begin, end] : ranges) {
            builder.onSortedRange(*scene.cloud(), begin, end);
            frame();
        }
        builder.finish();
        builder.wait();
        frame();
        frame(); // converged: nothing new
        QCOMPARE(view.lastFrameStats().leavesFirstDrawn, std::size_t{0});
        const std::size_t leaves = builder.hierarchy().insertionCount();
        QVERIFY(leaves > 0);
        QCOMPARE(firstDrawn, leaves);
        QVERIFY(framesWithLeaves >= 2);
        QVERIFY(delaysOrdered);
    }

    // The renderer reads the hierarchy while the builder grows it (another thread): every
    // frame shows a consistent part of the cloud, and the part grows as input arrives.
    void coverageGrowsWhileABuildRuns() {
        const QString path = test::sharedDataFile("lion.ply");
        if (path.isEmpty()) {
            QSKIP("../shared/data/lion.ply is absent");
        }
        auto reader = openPointCloud(path.toStdString());
        SortOptions sortOptions;
        sortOptions.batchPoints = 20000;
        IncrementalMortonSorter sorter(reader->info(), sortOptions);
        reader->read([&](const PointBatch& batch) { sorter.add(batch); });
        std::vector<std::pair<std::size_t, std::size_t>> ranges;
        sorter.sortAndEmit([&](const SortedCloud&, std::size_t begin, std::size_t end) {
            ranges.emplace_back(begin, end);
        });
        QVERIFY(ranges.size() >= 10);

        HierarchyBuilder builder(sorter.cloud(), BuildOptions{});
        CloudView view;
        view.setRenderSettings(plainSettings());
        view.setHierarchy(builder.sharedHierarchy());
        ViewCamera camera; // a fixed camera on the whole cube, so coverage can only grow
        camera.setSceneBox(glm::dvec3(0.0), glm::dvec3(1.0));
        camera.setStandardView(StandardView::Front);
        view.setCamera(camera);

        std::vector<double> coverages;
        const std::size_t step = (ranges.size() + 5) / 6;
        for (std::size_t i = 0; i < ranges.size(); ++i) {
            builder.onSortedRange(*sorter.cloud(), ranges[i].first, ranges[i].second);
            if (i % step == step - 1) {
                coverages.push_back(
                    test::coverage(view.renderImage(QSize(200, 200)), test::viewBackground()));
            }
        }
        builder.finish();
        builder.wait();
        coverages.push_back(
            test::coverage(view.renderImage(QSize(200, 200)), test::viewBackground()));
        QString trace;
        for (double c : coverages) {
            trace += QString::number(c, 'f', 4) + " ";
        }
        QVERIFY2(coverages.back() > 0.05, qPrintable(trace));
        QVERIFY2(coverages.back() > coverages.front(), qPrintable(trace));
        for (std::size_t i = 1; i < coverages.size(); ++i) {
            // Monotonic up to the few pixels a parent's splats differ from its children's.
            QVERIFY2(coverages[i] >= coverages[i - 1] - 0.005, qPrintable(trace));
        }
    }
};

QTEST_MAIN(tst_CloudViewGL)
#include "tst_cloudview_gl.moc"
