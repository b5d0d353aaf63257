#include "cloud_view.hpp"

#include "axis_gizmo_node.hpp"
#include "build/hierarchy.hpp"
#include "cloud_node.hpp"
#include "edl_pass.hpp"
#include "front/front_pick.hpp"
#include "overlay_node.hpp"
#include "points/las_fields.hpp"
#include "scale_bar.hpp"
#include "sort/morton_sorter.hpp"
#include "view_camera.hpp"

#include <QElapsedTimer>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFramebufferObject>
#include <QPainter>
#include <QSet>
#include <QTimer>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_inverse.hpp>
#include <limits>
#include <optional>

namespace omicron {

namespace {

constexpr int kFrameIntervalMs = 16; // the repaint and fly timer: ~60 Hz
constexpr double kWheelZoomPerNotch = 0.85;
constexpr std::size_t kBoundsPointsPerFrame = std::size_t{4} << 20;
constexpr float kBackground[3] = {0.11f, 0.12f, 0.14f}; // dark slate, as point viewers use

} // namespace

class CloudViewPrivate {
public:
    SceneGraph scene;
    CloudNode* cloud = nullptr;
    OverlayNode* overlay = nullptr;
    ViewCamera camera;
    RenderSettings settings;
    FrameStats lastStats;
    bool autoFit = true; // frame the cloud until the user moves the camera
    bool glReady = false;
    QString glError;
    QString glRenderer;
    bool flyMode = false;
    QSet<int> flyKeys;
    QTimer frameTimer;
    QElapsedTimer flyClock;
    QElapsedTimer fpsClock;   // start of the current fps window
    QElapsedTimer frameClock; // since the last frame drawn
    int framesThisSecond = 0;
    double fps = 0.0;
    QPoint lastMouse;
    Qt::MouseButtons dragButtons;
    QMetaObject::Connection contextConnection;
    EdlPass edl;
    bool hoverPicking = false;
    std::optional<MeasureKind> measureTool;
    std::vector<Measurement> measurements;
    std::optional<Measurement> draft; // the measurement being taken
    QPoint pressPosition;
    bool releaseEndsDoubleClick = false; // the release after a double-click adds no point
    QTimer hoverTimer;                   // a pick once the pointer rests
    QPoint hoverPosition;

    CloudViewPrivate() {
        auto cloudNode = std::make_unique<CloudNode>();
        cloud = scene.add(std::move(cloudNode));
        overlay = scene.add(std::make_unique<OverlayNode>(*cloud));
        scene.add(std::make_unique<AxisGizmoNode>());
    }

    // Frames keep coming while anything can still change without user input.
    bool needsMoreFrames() const {
        if (!flyKeys.isEmpty()) {
            return true;
        }
        if (const auto& hierarchy = cloud->hierarchy()) {
            // Still building, leaves waiting for substitution, uploads cut by the budget, a
            // front sweep cut by its time budget, or points not yet in the bounds.
            return !hierarchy->publishedCut().complete || lastStats.placeholders > 0 ||
                   lastStats.uploads > 0 || lastStats.frontMs >= settings.frontBudgetMs * 0.9 ||
                   cloud->boundsPending() || lastStats.pendingLoads > 0 ||
                   (hierarchy->residency() != nullptr &&
                    hierarchy->residency()->stats().pendingLoads > 0);
        }
        return false; // a preview changes only through setPreview(), which repaints
    }

    bool edlWanted() const {
        switch (settings.edl) {
        case EdlMode::On:
            return true;
        case EdlMode::Off:
            return false;
        case EdlMode::Auto:
            return cloud->hierarchy() != nullptr && !cloud->hasColor();
        }
        return false;
    }

    // The scene into `framebuffer`; with eye-dome lighting, the cloud (node 0) first into
    // the EDL target, shaded into the frame, and the overlays over it.
    void renderScene(RenderContext& context, unsigned framebuffer) {
        QOpenGLExtraFunctions& gl = *context.gl;
        context.stats->eyeDomeLighting =
            edlWanted() && edl.begin(gl, context.widthPx, context.heightPx, kBackground);
        if (!context.stats->eyeDomeLighting) {
            context.targetFramebuffer = framebuffer;
            scene.render(context);
            return;
        }
        context.targetFramebuffer = edl.framebuffer();
        scene.render(context, 0, 1);
        context.targetFramebuffer = framebuffer;
        edl.composite(gl, framebuffer, context.projection, camera.orthographic(),
                      settings.edlStrength, settings.edlRadiusPx);
        scene.render(context, 1, scene.size());
    }

    // What is painted over the GL frame with QPainter, in a `size` view (the widget, or a
    // screenshot image): each measurement's value beside it, the scale bar and the north arrow.
    void paintOverlays(QPainter& painter, const QSizeF& size, double heightPx) {
        const auto& hierarchy = cloud->hierarchy();
        if (hierarchy == nullptr) {
            return;
        }
        const CubeTransform& cube = hierarchy->cloud().cube();
        const glm::dmat4 viewProjection =
            camera.projectionMatrix(size.width() / std::max(1.0, size.height())) *
            camera.viewMatrix();
        const auto toScreen = [&](const glm::dvec3& unit) -> std::optional<QPointF> {
            const glm::dvec4 clip = viewProjection * glm::dvec4(unit, 1.0);
            if (clip.w <= 0.0) {
                return std::nullopt; // behind the camera
            }
            return QPointF((clip.x / clip.w * 0.5 + 0.5) * size.width(),
                           (0.5 - clip.y / clip.w * 0.5) * size.height());
        };
        painter.setRenderHint(QPainter::Antialiasing);
        const QFontMetrics metrics(painter.font());
        const auto textBox = [&](const QPointF& at, const QString& text, const QColor& color) {
            const QRectF box(at, QSizeF(metrics.horizontalAdvance(text) + 8, metrics.height() + 4));
            painter.fillRect(box, QColor(0, 0, 0, 170));
            painter.setPen(color);
            painter.drawText(box, Qt::AlignCenter, text);
        };
        const auto label = [&](const Measurement& measurement) {
            if (measurement.points.size() < 2) {
                return;
            }
            // At the middle of the last segment (a distance: of the segment itself).
            const glm::dvec3 middle =
                (measurement.points[measurement.points.size() - 2] + measurement.points.back()) *
                0.5;
            if (const auto at = toScreen((middle - cube.origin) / cube.edge)) {
                textBox(*at + QPointF(6, -metrics.height() - 4), measurement.valueText(),
                        QColor(255, 220, 40));
            }
        };
        for (const Measurement& measurement : measurements) {
            label(measurement);
        }
        if (draft) {
            label(*draft);
        }
        if (settings.showScaleBar) {
            // File units per pixel at the pivot (anywhere, in an orthographic view, which is
            // as high as the perspective one at the pivot).
            const double unitsPerPixel = camera.distance() /
                                         camera.pixelsPerUnitAtUnitDistance(heightPx) * cube.edge *
                                         (heightPx / size.height());
            const ScaleBar bar = scaleBarFor(unitsPerPixel, size.width() / 6.0);
            if (bar.widthPx > 0.0) {
                const QPointF right(size.width() - 16.0, size.height() - 16.0);
                const QPointF left = right - QPointF(bar.widthPx, 0.0);
                painter.setPen(QPen(QColor(235, 235, 235), 2.0));
                painter.drawLine(left, right);
                painter.drawLine(left, left - QPointF(0, 6));
                painter.drawLine(right, right - QPointF(0, 6));
                textBox(
                    QPointF(left.x() + (bar.widthPx - metrics.horizontalAdvance(bar.label) - 8) / 2,
                            left.y() - metrics.height() - 12),
                    bar.label, QColor(235, 235, 235));
            }
        }
        // Georeferenced: the file names its coordinate system (LAS projection records), or
        // its coordinates look projected (10^4 units or more from the origin).
        const bool georeferenced =
            !hierarchy->cloud().lasProjectionRecords().empty() ||
            std::max(std::abs(cube.origin.x), std::abs(cube.origin.y)) >= 1e4;
        if (settings.showNorthArrow && georeferenced) {
            // +y seen from the pivot, as a direction on screen.
            const auto from = toScreen(camera.pivot());
            const auto to =
                toScreen(camera.pivot() + glm::dvec3(0.0, 0.05, 0.0) * camera.distance());
            if (from && to && *from != *to) {
                QPointF direction = *to - *from;
                direction /= std::hypot(direction.x(), direction.y());
                // Room around it for the arrow and its N whichever way north points.
                const QPointF centre(size.width() - 42.0, 42.0);
                const QPointF tip = centre + direction * 16.0;
                const QPointF tail = centre - direction * 16.0;
                const QPointF side(-direction.y() * 7.0, direction.x() * 7.0);
                painter.setPen(QPen(QColor(235, 235, 235), 2.0));
                painter.drawLine(tail, tip);
                painter.setBrush(QColor(235, 235, 235));
                painter.drawPolygon(
                    QPolygonF({tip, tip - direction * 12.0 + side, tip - direction * 12.0 - side}));
                painter.drawText(QRectF(tip + direction * 10.0 - QPointF(8, 8), QSizeF(16, 16)),
                                 Qt::AlignCenter, QStringLiteral("N"));
            }
        }
    }

    // The measurements (and the one being taken) as unit-cube polylines for the overlay.
    void updateMeasurementLines() {
        std::vector<std::vector<glm::dvec3>> lines;
        const auto& hierarchy = cloud->hierarchy();
        if (hierarchy != nullptr) {
            const CubeTransform& cube = hierarchy->cloud().cube();
            const auto add = [&](const Measurement& measurement) {
                std::vector<glm::dvec3> line;
                for (const glm::dvec3& p : measurement.points) {
                    line.push_back((p - cube.origin) / cube.edge);
                }
                if (measurement.kind == MeasureKind::Area && measurement.complete() &&
                    !line.empty()) {
                    line.push_back(line.front());
                }
                lines.push_back(std::move(line));
            };
            for (const Measurement& measurement : measurements) {
                add(measurement);
            }
            if (draft) {
                add(*draft);
            }
        }
        overlay->setMeasurementLines(std::move(lines));
    }

    struct SurfacePick {
        glm::dvec3 position; // unit cube
        double pixelSize;    // unit-cube length of one pixel at that depth
    };

    // The nearest depth the last frame drew within a few pixels of `position`, unprojected.
    std::optional<SurfacePick> pickDepth(CloudView& view, const QPoint& position) {
        if (!glReady) {
            return std::nullopt;
        }
        const qreal ratio = view.devicePixelRatioF();
        const int widthPx = std::max(1, static_cast<int>(std::lround(view.width() * ratio)));
        const int heightPx = std::max(1, static_cast<int>(std::lround(view.height() * ratio)));
        const int x = static_cast<int>(position.x() * ratio);
        const int y = heightPx - 1 - static_cast<int>(position.y() * ratio);
        view.makeCurrent();
        QOpenGLExtraFunctions& gl = *view.context()->extraFunctions();
        gl.glBindFramebuffer(GL_FRAMEBUFFER, view.defaultFramebufferObject());
        // The nearest depth in a small window: points are sparse, a single pixel often misses.
        constexpr int kRadius = 4;
        const int x0 = std::clamp(x - kRadius, 0, widthPx - 1);
        const int y0 = std::clamp(y - kRadius, 0, heightPx - 1);
        const int w = std::min(2 * kRadius + 1, widthPx - x0);
        const int h = std::min(2 * kRadius + 1, heightPx - y0);
        std::vector<float> depths(static_cast<std::size_t>(w * h), 1.0f);
        gl.glReadPixels(x0, y0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depths.data());
        view.doneCurrent();
        std::size_t best = 0;
        for (std::size_t i = 1; i < depths.size(); ++i) {
            if (depths[i] < depths[best]) {
                best = i;
            }
        }
        if (depths.empty() || depths[best] >= 1.0f) {
            return std::nullopt;
        }
        const double px = x0 + static_cast<double>(best % static_cast<std::size_t>(w)) + 0.5;
        const double py = y0 + static_cast<double>(best / static_cast<std::size_t>(w)) + 0.5;
        const glm::dmat4 inverse = glm::inverse(
            camera.projectionMatrix(static_cast<double>(widthPx) / heightPx) * camera.viewMatrix());
        const auto unproject = [&](double sx, double sy) {
            const glm::dvec4 world =
                inverse * glm::dvec4(sx / widthPx * 2.0 - 1.0, sy / heightPx * 2.0 - 1.0,
                                     depths[best] * 2.0 - 1.0, 1.0);
            return glm::dvec3(world) / world.w;
        };
        const glm::dvec3 at = unproject(px, py);
        return SurfacePick{at, glm::length(unproject(px + 1.0, py) - at)};
    }

    // Until the user navigates, the camera keeps framing the cloud as its known bounds grow
    // (a build publishes the cloud in Morton order, one region after another).
    void applyAutoFit() {
        if (autoFit && cloud->hasBounds()) {
            camera.setSceneBox(cloud->boundsMin(), cloud->boundsMax());
            camera.fit();
        }
    }
};

void useCoreProfileByDefault() {
    QSurfaceFormat format;
    format.setVersion(4, 5);
    format.setProfile(QSurfaceFormat::CoreProfile);
    format.setDepthBufferSize(24);
    QSurfaceFormat::setDefaultFormat(format);
}

CloudView::CloudView(QWidget* parent)
    : QOpenGLWidget(parent), d(std::make_unique<CloudViewPrivate>()) {
    qRegisterMetaType<omicron::FrameStats>();
    qRegisterMetaType<omicron::RenderSettings>();
    qRegisterMetaType<omicron::PickedPoint>();
    QSurfaceFormat surfaceFormat = format();
    surfaceFormat.setVersion(3, 3);
    surfaceFormat.setProfile(QSurfaceFormat::CoreProfile);
    surfaceFormat.setDepthBufferSize(24);
    surfaceFormat.setSamples(0); // the depth under the cursor is read back for picking
    setFormat(surfaceFormat);
    setFocusPolicy(Qt::StrongFocus);
    setMinimumSize(160, 120);
    d->frameTimer.setInterval(kFrameIntervalMs);
    connect(&d->frameTimer, &QTimer::timeout, this, [this] {
        if (!d->flyKeys.isEmpty()) {
            const double seconds = std::min(d->flyClock.restart() * 1e-3, 0.1);
            glm::dvec3 direction(0.0);
            direction.z += d->flyKeys.contains(Qt::Key_W) ? 1.0 : 0.0;
            direction.z -= d->flyKeys.contains(Qt::Key_S) ? 1.0 : 0.0;
            direction.x += d->flyKeys.contains(Qt::Key_D) ? 1.0 : 0.0;
            direction.x -= d->flyKeys.contains(Qt::Key_A) ? 1.0 : 0.0;
            direction.y += d->flyKeys.contains(Qt::Key_E) ? 1.0 : 0.0;
            direction.y -= d->flyKeys.contains(Qt::Key_Q) ? 1.0 : 0.0;
            d->camera.fly(direction, seconds);
        }
        update();
    });
    d->fpsClock.start();
    d->hoverTimer.setSingleShot(true);
    d->hoverTimer.setInterval(40);
    connect(&d->hoverTimer, &QTimer::timeout, this, [this] {
        if (const auto point = pickCloudPoint(d->hoverPosition)) {
            emit pointHovered(*point);
        } else {
            emit hoverLeftCloud();
        }
    });
}

CloudView::~CloudView() {
    // The base class destroys the context after `d` is gone: nothing may react to it then.
    disconnect(d->contextConnection);
    if (d->glReady && context() != nullptr) {
        makeCurrent();
        d->scene.releaseGL(*context()->extraFunctions());
        d->edl.releaseGL(*context()->extraFunctions());
        doneCurrent();
    }
}

void CloudView::setHierarchy(std::shared_ptr<const Hierarchy> hierarchy) {
    const bool first = d->cloud->hierarchy() == nullptr && hierarchy != nullptr;
    d->cloud->setHierarchy(std::move(hierarchy));
    if (first) {
        d->autoFit = true;
    }
    update();
}

std::shared_ptr<const Hierarchy> CloudView::hierarchy() const {
    return d->cloud->hierarchy();
}

void CloudView::setPreview(const PreviewSample& preview, const CubeTransform& cube) {
    (void)cube; // preview positions are already in the unit cube of `cube`
    std::vector<PointVertex> vertices(preview.positions.size());
    glm::vec3 low(1.0f), high(0.0f);
    for (const glm::vec3& p : preview.positions) {
        low = glm::min(low, p);
        high = glm::max(high, p);
    }
    // A preview point stands for pointsSeen / samples input points: size its splat so the
    // sample covers the area the cloud would (a surface of the box's two largest extents).
    const glm::vec3 extent = glm::max(high - low, glm::vec3(0.0f));
    const float area =
        std::max({extent.x * extent.y, extent.x * extent.z, extent.y * extent.z, 1e-12f});
    const float radius =
        vertices.empty() ? 0.0f : 0.6f * std::sqrt(area / static_cast<float>(vertices.size()));
    for (std::size_t i = 0; i < vertices.size(); ++i) {
        PointVertex& v = vertices[i];
        v.x = preview.positions[i].x;
        v.y = preview.positions[i].y;
        v.z = preview.positions[i].z;
        if (i < preview.colors.size()) {
            v.r = preview.colors[i].r;
            v.g = preview.colors[i].g;
            v.b = preview.colors[i].b;
        } else {
            v.r = v.g = v.b = 200;
        }
        v.radius = radius;
    }
    d->cloud->setPreview(std::move(vertices));
    update();
}

void CloudView::clearPreview() {
    d->cloud->setPreview({});
    update();
}

RenderSettings CloudView::renderSettings() const {
    return d->settings;
}

void CloudView::setRenderSettings(const RenderSettings& settings) {
    if (settings == d->settings) {
        return;
    }
    d->settings = settings;
    emit renderSettingsChanged(settings);
    update();
}

void CloudView::setClassVisible(int classification, bool visible) {
    if (classification < 0 || classification >= kLasClassCount) {
        return;
    }
    RenderSettings settings = d->settings;
    settings.hiddenClasses.set(static_cast<std::size_t>(classification), !visible);
    setRenderSettings(settings);
}

bool CloudView::isClassVisible(int classification) const {
    return classification < 0 || classification >= kLasClassCount ||
           !d->settings.hiddenClasses.test(static_cast<std::size_t>(classification));
}

ViewCamera CloudView::camera() const {
    return d->camera;
}

void CloudView::setCamera(const ViewCamera& camera) {
    d->camera = camera;
    d->autoFit = false;
    update();
}

void CloudView::fitToCloud() {
    d->autoFit = true;
    d->applyAutoFit();
    update();
}

void CloudView::setStandardView(StandardView view) {
    if (d->cloud->hasBounds()) {
        d->camera.setSceneBox(d->cloud->boundsMin(), d->cloud->boundsMax());
    }
    d->camera.setStandardView(view);
    d->autoFit = true; // the box may still grow: keep framing it from this direction
    update();
}

void CloudView::setFlyMode(bool on) {
    if (on == d->flyMode) {
        return;
    }
    d->flyMode = on;
    emit flyModeChanged(on);
}

void CloudView::setOrthographic(bool on) {
    d->camera.setOrthographic(on);
    update();
}

bool CloudView::orthographic() const {
    return d->camera.orthographic();
}

bool CloudView::flyMode() const {
    return d->flyMode;
}

void CloudView::setHighlightedNode(int level, std::uint64_t code) {
    if (!morton::isValid(code) || morton::level(code) != level) {
        qWarning("omicron::CloudView: node code %llx is not of level %d; highlight cleared",
                 static_cast<unsigned long long>(code), level);
        clearHighlightedNode();
        return;
    }
    if (d->overlay->highlight() != code) {
        d->overlay->setHighlight(code);
        update();
    }
}

void CloudView::clearHighlightedNode() {
    if (d->overlay->highlight()) {
        d->overlay->setHighlight(std::nullopt);
        update();
    }
}

std::optional<std::uint64_t> CloudView::highlightedNode() const {
    return d->overlay->highlight();
}

FrameStats CloudView::lastFrameStats() const {
    return d->lastStats;
}

QString CloudView::glErrorString() const {
    return d->glError;
}

QString CloudView::glRendererName() const {
    return d->glRenderer;
}

bool CloudView::computePointsAvailable() const {
    return d->glReady && d->cloud->computePointsAvailable();
}

void CloudView::initializeGL() {
    QOpenGLContext* glContext = context();
    d->glRenderer = QString::fromLatin1(
        reinterpret_cast<const char*>(glContext->functions()->glGetString(GL_RENDERER)));
    const QSurfaceFormat actual = glContext->format();
    if (actual.majorVersion() < 3 || (actual.majorVersion() == 3 && actual.minorVersion() < 3)) {
        d->glError = QStringLiteral("OpenGL 3.3 or newer is needed; this context has %1.%2")
                         .arg(actual.majorVersion())
                         .arg(actual.minorVersion());
        qWarning("omicron::CloudView: %s", qPrintable(d->glError));
        return;
    }
    try {
        d->scene.initializeGL(*glContext->extraFunctions());
        d->edl.initializeGL();
        d->glReady = true;
    } catch (const std::exception& error) {
        d->glError = QString::fromStdString(error.what());
        qWarning("omicron::CloudView: %s", qPrintable(d->glError));
        return;
    }
    // GL resources belong to this context: free them while it still exists (the widget may
    // be re-parented, which gives it a new context and a new initializeGL()).
    disconnect(d->contextConnection);
    d->contextConnection = connect(glContext, &QOpenGLContext::aboutToBeDestroyed, this, [this] {
        if (d->glReady) {
            makeCurrent();
            d->scene.releaseGL(*context()->extraFunctions());
            d->edl.releaseGL(*context()->extraFunctions());
            d->glReady = false;
            doneCurrent();
        }
    });
    d->frameTimer.start();
}

FrameStats CloudView::renderFrame(unsigned framebuffer, int widthPx, int heightPx, bool settle) {
    QElapsedTimer timer;
    timer.start();
    FrameStats stats;
    QOpenGLExtraFunctions& gl = *context()->extraFunctions();
    gl.glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl.glViewport(0, 0, widthPx, heightPx);
    gl.glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
    gl.glClearDepthf(1.0f);
    gl.glDepthMask(GL_TRUE);
    gl.glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (!d->glReady) {
        return stats;
    }
    // Bounded work per frame while a build publishes points; everything for a screenshot.
    d->cloud->updateBounds(settle ? std::numeric_limits<std::size_t>::max()
                                  : kBoundsPointsPerFrame);
    d->applyAutoFit();
    if (d->cloud->hasBounds()) {
        d->camera.setSceneBox(d->cloud->boundsMin(), d->cloud->boundsMax());
    }

    d->updateMeasurementLines();
    RenderContext renderContext;
    renderContext.gl = &gl;
    renderContext.camera = &d->camera;
    renderContext.settings = &d->settings;
    renderContext.view = d->camera.viewMatrix();
    renderContext.projection =
        d->camera.projectionMatrix(static_cast<double>(widthPx) / std::max(heightPx, 1));
    renderContext.widthPx = widthPx;
    renderContext.heightPx = heightPx;
    renderContext.targetFramebuffer = framebuffer;
    renderContext.settle = settle;
    renderContext.stats = &stats;
    d->renderScene(renderContext, framebuffer);
    if (settle) {
        // A second pass draws what the first uploaded (the front converged in the first).
        gl.glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
        gl.glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
        gl.glDepthMask(GL_TRUE);
        gl.glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        stats = FrameStats{};
        d->renderScene(renderContext, framebuffer);
    }
    const FirstDrawTracker::Delays firstDraws = d->cloud->takeFirstDraws();
    stats.leavesFirstDrawn = firstDraws.leaves;
    stats.leafDrawDelayMedianMs = firstDraws.medianMs;
    stats.leafDrawDelayMaxMs = firstDraws.maxMs;
    stats.frameMs = static_cast<double>(timer.nsecsElapsed()) * 1e-6;
    return stats;
}

void CloudView::paintGL() {
    const qreal ratio = devicePixelRatioF();
    const int widthPx = std::max(1, static_cast<int>(std::lround(width() * ratio)));
    const int heightPx = std::max(1, static_cast<int>(std::lround(height() * ratio)));
    FrameStats stats = renderFrame(defaultFramebufferObject(), widthPx, heightPx, false);
    {
        QPainter painter(this);
        d->paintOverlays(painter, QSizeF(size()), heightPx);
    }

    // Frames are drawn on demand: after a pause (no input, nothing to refine) a new window
    // starts with this frame, so the rate is that of rendering, not diluted by the idle time.
    constexpr qint64 kIdleMs = 1000;
    const qint64 sinceLastFrameMs = d->frameClock.isValid() ? d->frameClock.restart() : kIdleMs + 1;
    if (!d->frameClock.isValid()) {
        d->frameClock.start();
    }
    if (sinceLastFrameMs > kIdleMs) {
        d->framesThisSecond = 0;
        d->fpsClock.restart();
    }
    ++d->framesThisSecond;
    const qint64 elapsedMs = d->fpsClock.elapsed();
    if (elapsedMs >= 1000) {
        d->fps = d->framesThisSecond * 1000.0 / static_cast<double>(elapsedMs);
        d->framesThisSecond = 0;
        d->fpsClock.restart();
    }
    stats.fps = d->fps;
    d->lastStats = stats;
    emit frameRendered(stats);
    if (d->needsMoreFrames()) {
        if (!d->frameTimer.isActive()) {
            d->frameTimer.start();
        }
    } else if (d->flyKeys.isEmpty()) {
        d->frameTimer.stop();
    }
}

QImage CloudView::renderImage(const QSize& size) {
    if (context() == nullptr || !isValid()) {
        // Never shown: create the native window and the context without mapping it.
        setAttribute(Qt::WA_DontShowOnScreen);
        resize(size);
        show();
    }
    if (!isValid()) {
        return {};
    }
    makeCurrent();
    QOpenGLFramebufferObject target(size, QOpenGLFramebufferObject::Depth);
    const FrameStats stats = renderFrame(target.handle(), size.width(), size.height(), true);
    QImage image = target.toImage(); // flipped: GL rows go bottom-up
    d->lastStats = stats;
    doneCurrent();
    QPainter painter(&image); // labels, scale bar and north arrow in the image too
    d->paintOverlays(painter, QSizeF(size), size.height());
    return image;
}

std::optional<QVector3D> CloudView::pickPoint(const QPoint& position) {
    const auto picked = d->pickDepth(*this, position);
    if (!picked) {
        return std::nullopt;
    }
    return QVector3D(static_cast<float>(picked->position.x), static_cast<float>(picked->position.y),
                     static_cast<float>(picked->position.z));
}

std::optional<PickedPoint> CloudView::pickCloudPoint(const QPoint& position) {
    const Front* front = d->cloud->front();
    const auto& hierarchy = d->cloud->hierarchy();
    if (front == nullptr || hierarchy == nullptr) {
        return std::nullopt;
    }
    const auto surface = d->pickDepth(*this, position);
    if (!surface) {
        return std::nullopt;
    }
    // A drawn point's disc may cover many pixels around it (a coarse node's splats are large):
    // search that far; the nearest point wins.
    constexpr double kSearchPixels = 32.0;
    const auto drawn = nearestDrawnPoint(*hierarchy, front->entries(), surface->position,
                                         kSearchPixels * surface->pixelSize);
    if (!drawn) {
        return std::nullopt;
    }
    const SortedCloud& cloud = hierarchy->cloud();
    PickedPoint point;
    point.unitPosition = drawn->unitPosition;
    point.source = cloud.cube().toSource(drawn->unitPosition);
    point.level = morton::level(drawn->node);
    point.cloudIndex = drawn->cloudIndex;
    point.hasColor = cloud.attributes().has(Attribute::Color);
    point.color = point.hasColor ? cloud.color(drawn->cloudIndex) : glm::u8vec3(0);
    point.hasIntensity = cloud.attributes().has(Attribute::Intensity);
    point.intensity = point.hasIntensity ? cloud.intensities()[drawn->cloudIndex] : 0;
    const AttributeSet attributes = cloud.attributes();
    point.hasLas = attributes.has(Attribute::Las);
    if (point.hasLas) {
        const LasFields las = decodeLasFields(attributes, cloud.lasRecord(drawn->cloudIndex));
        point.classification = las.classification;
        point.returnNumber = static_cast<std::uint8_t>(las.returnNumber());
        point.numberOfReturns = static_cast<std::uint8_t>(las.numberOfReturns());
        point.lasFlags = las.flags;
        point.userData = las.userData;
        point.pointSourceId = las.pointSourceId;
        point.scanAngleDegrees = las.scanAngleDegrees();
        point.hasGpsTime = attributes.has(Attribute::GpsTime);
        point.gpsTime = las.gpsTime;
    }
    return point;
}

void CloudView::setHoverPicking(bool on) {
    d->hoverPicking = on;
    setMouseTracking(on || hasMouseTracking());
    if (!on) {
        d->hoverTimer.stop();
    }
}

void CloudView::setMeasureTool(std::optional<MeasureKind> tool) {
    d->measureTool = tool;
    if (d->draft) {
        d->draft.reset();
        emit measurementsChanged();
    }
    setCursor(tool ? Qt::CrossCursor : Qt::ArrowCursor);
    update();
}

std::optional<MeasureKind> CloudView::measureTool() const {
    return d->measureTool;
}

bool CloudView::addMeasurePoint(const QPoint& position) {
    if (!d->measureTool) {
        return false;
    }
    const auto point = pickCloudPoint(position); // snaps to the drawn point under the cursor
    if (!point) {
        return false;
    }
    if (!d->draft) {
        d->draft = Measurement();
        d->draft->kind = *d->measureTool;
    }
    d->draft->points.push_back(point->source);
    if (d->draft->complete()) {
        d->measurements.push_back(*d->draft);
        d->draft.reset();
    }
    emit measurementsChanged();
    update();
    return true;
}

void CloudView::finishMeasurement() {
    if (!d->draft || !d->draft->canFinish()) {
        return;
    }
    d->draft->finish();
    d->measurements.push_back(*d->draft);
    d->draft.reset();
    emit measurementsChanged();
    update();
}

const std::vector<Measurement>& CloudView::measurements() const {
    return d->measurements;
}

const Measurement* CloudView::measurementInProgress() const {
    return d->draft ? &*d->draft : nullptr;
}

void CloudView::removeMeasurement(std::size_t index) {
    if (index < d->measurements.size()) {
        d->measurements.erase(d->measurements.begin() + static_cast<std::ptrdiff_t>(index));
        emit measurementsChanged();
        update();
    }
}

void CloudView::clearMeasurements() {
    if (!d->measurements.empty() || d->draft) {
        d->measurements.clear();
        d->draft.reset();
        emit measurementsChanged();
        update();
    }
}

void CloudView::mousePressEvent(QMouseEvent* event) {
    d->lastMouse = event->position().toPoint();
    d->pressPosition = d->lastMouse;
    d->dragButtons = event->buttons();
}

void CloudView::mouseReleaseEvent(QMouseEvent* event) {
    d->dragButtons = event->buttons();
    const QPoint position = event->position().toPoint();
    const bool click = (position - d->pressPosition).manhattanLength() <= 3;
    if (d->releaseEndsDoubleClick) {
        d->releaseEndsDoubleClick = false;
    } else if (click && event->button() == Qt::LeftButton && d->measureTool) {
        addMeasurePoint(position);
    }
}

void CloudView::mouseMoveEvent(QMouseEvent* event) {
    const QPoint position = event->position().toPoint();
    const QPoint delta = position - d->lastMouse;
    d->lastMouse = position;
    const bool panning =
        (event->buttons() & (Qt::RightButton | Qt::MiddleButton)) ||
        ((event->buttons() & Qt::LeftButton) && (event->modifiers() & Qt::ShiftModifier));
    if (panning) {
        d->camera.pan(delta.x(), delta.y(), height());
    } else if (event->buttons() & Qt::LeftButton) {
        if (d->flyMode) {
            d->camera.look(delta.x(), delta.y());
        } else {
            d->camera.orbit(delta.x(), delta.y());
        }
    } else {
        if (d->hoverPicking) {
            d->hoverPosition = position;
            d->hoverTimer.start(); // picks when the pointer rests (reading depth costs a sync)
        }
        return;
    }
    d->autoFit = false;
    update();
}

void CloudView::leaveEvent(QEvent* event) {
    QOpenGLWidget::leaveEvent(event);
    if (d->hoverPicking) {
        d->hoverTimer.stop();
        emit hoverLeftCloud();
    }
}

void CloudView::mouseDoubleClickEvent(QMouseEvent* event) {
    if (d->measureTool) {
        d->releaseEndsDoubleClick = true;
        finishMeasurement(); // a polyline or an area ends at its last point
        return;
    }
    if (const auto picked = pickPoint(event->position().toPoint())) {
        d->camera.setPivot(glm::dvec3(picked->x(), picked->y(), picked->z()));
        d->autoFit = false;
        update();
    }
}

void CloudView::wheelEvent(QWheelEvent* event) {
    const double notches = event->angleDelta().y() / 120.0;
    if (notches == 0.0) {
        return;
    }
    const double factor = std::pow(kWheelZoomPerNotch, notches);
    // Zoom to the point under the cursor; over empty space, towards the pivot.
    const auto picked = pickPoint(event->position().toPoint());
    const glm::dvec3 target =
        picked ? glm::dvec3(picked->x(), picked->y(), picked->z()) : d->camera.pivot();
    d->camera.zoomToward(target, factor);
    d->autoFit = false;
    update();
}

void CloudView::keyPressEvent(QKeyEvent* event) {
    switch (event->key()) {
    case Qt::Key_W:
    case Qt::Key_A:
    case Qt::Key_S:
    case Qt::Key_D:
    case Qt::Key_Q:
    case Qt::Key_E:
        if (!event->isAutoRepeat()) {
            if (d->flyKeys.isEmpty()) {
                d->flyClock.restart();
            }
            d->flyKeys.insert(event->key());
            d->autoFit = false;
            d->frameTimer.start();
        }
        return;
    case Qt::Key_F:
        fitToCloud();
        return;
    case Qt::Key_Return:
    case Qt::Key_Enter:
        if (d->draft) {
            finishMeasurement();
            return;
        }
        break;
    case Qt::Key_Escape:
        if (d->draft) {
            d->draft.reset();
            emit measurementsChanged();
            update();
            return;
        }
        break;
    default:
        QOpenGLWidget::keyPressEvent(event);
    }
}

void CloudView::keyReleaseEvent(QKeyEvent* event) {
    if (!event->isAutoRepeat() && d->flyKeys.remove(event->key())) {
        return;
    }
    QOpenGLWidget::keyReleaseEvent(event);
}

} // namespace omicron
