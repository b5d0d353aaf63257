// omicron::CloudView: the embeddable QOpenGLWidget that draws a hierarchy while it is built.
//
// Give it a hierarchy (a HierarchyBuilder's, or one being loaded from a .omh file) and it
// tracks the renderable part with a Front on the GUI thread, uploads node buffers within a
// per-frame budget and draws them as points or surface splats. Builder threads never call GL.
// Until the first sorted batch exists, a preview sample (the sorter's) can be shown instead.
#pragma once

#include "measurement.hpp"
#include "render_settings.hpp"
#include "view_camera.hpp"

#include <QOpenGLWidget>
#include <QVector3D>
#include <memory>
#include <optional>
#include <vector>

namespace omicron {

class Hierarchy;
struct PreviewSample;
struct CubeTransform;
class CloudViewPrivate;

// Makes an OpenGL 4.5 core profile with a 24-bit depth buffer the default surface format, so
// every context of the application (the views' and those sharing with them) can run the
// compute rasterizer. Call before the QApplication's first window.
void useCoreProfileByDefault();

class CloudView : public QOpenGLWidget {
    Q_OBJECT
public:
    explicit CloudView(QWidget* parent = nullptr);
    ~CloudView() override;

    // Shows `hierarchy` (nullptr: nothing). May be called at any time, also while the
    // hierarchy grows; the camera is fitted to it the first time a hierarchy is attached
    // (and on fitToCloud()).
    void setHierarchy(std::shared_ptr<const Hierarchy> hierarchy);
    std::shared_ptr<const Hierarchy> hierarchy() const;
    // Drawn while the attached hierarchy has nothing renderable yet (or none is attached).
    void setPreview(const PreviewSample& preview, const CubeTransform& cube);
    void clearPreview();

    RenderSettings renderSettings() const;
    void setRenderSettings(const RenderSettings& settings);
    // Shows or hides the points of one ASPRS class (0-255; others are ignored) in every render
    // mode: RenderSettings::hiddenClasses, edited (renderSettingsChanged is emitted).
    void setClassVisible(int classification, bool visible);
    bool isClassVisible(int classification) const;

    // Camera. Until the user navigates (or setCamera() is called), the view keeps framing the
    // cloud as its bounds grow during a build.
    ViewCamera camera() const;
    void setCamera(const ViewCamera& camera);
    void fitToCloud();
    void setStandardView(StandardView view);
    void setFlyMode(bool on);
    bool flyMode() const;
    // Orthographic projection (the camera's, kept with it by camera()/setCamera()).
    void setOrthographic(bool on);
    bool orthographic() const;

    // Draws the cell of one node as a box over the cloud (magenta, through the points),
    // whatever the overlay settings: e.g. the node selected in a tree of the hierarchy.
    // `code` is the node's Morton code with its sentinel bit; `level` must be its level
    // (a mismatch clears the highlight). The highlight stays until cleared or replaced.
    void setHighlightedNode(int level, std::uint64_t code);
    void clearHighlightedNode();
    std::optional<std::uint64_t> highlightedNode() const;

    // Statistics of the last frame drawn.
    FrameStats lastFrameStats() const;

    // Renders the current state at `size` into an image, with the front converged and every
    // node it draws uploaded (no visible window needed: a never-shown view creates its
    // context off screen). Empty image when no OpenGL 3.3 context could be made.
    QImage renderImage(const QSize& size);

    // The point under `position` (widget coordinates) in the hierarchy's unit cube, from the
    // depth of the last frame; nothing over empty space.
    std::optional<QVector3D> pickPoint(const QPoint& position);

    // The drawn point of the cloud nearest to `position` (within a few pixels of what the
    // last frame drew there), with its source coordinates and attributes; nothing over empty
    // space or before a hierarchy is drawn.
    std::optional<PickedPoint> pickCloudPoint(const QPoint& position);
    // Hovering with no button pressed picks (after the pointer rests 40 ms) and emits
    // pointHovered or hoverLeftCloud. Off by default; the app turns it on.
    void setHoverPicking(bool on);

    // The measure tool: while one is set, a click (press and release without moving) adds
    // the cloud point under it to the measurement being taken; a distance or height is done
    // at its second point, a polyline or area when finished (double-click, Enter). Escape
    // drops the unfinished one. nullopt: navigation only (an unfinished one is dropped).
    void setMeasureTool(std::optional<MeasureKind> tool);
    std::optional<MeasureKind> measureTool() const;
    // Adds the cloud point under `position` as a click does; false over empty space.
    bool addMeasurePoint(const QPoint& position);
    void finishMeasurement();
    // The finished measurements, oldest first, and the one being taken (if any).
    const std::vector<Measurement>& measurements() const;
    const Measurement* measurementInProgress() const;
    void removeMeasurement(std::size_t index);
    void clearMeasurements();

    // GL_RENDERER of the context (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"); empty before it exists.
    QString glRendererName() const;

    // Whether RenderMode::ComputePoints draws with compute shaders in this view's context
    // (OpenGL 4.3); when false it draws GL points. False before the context exists.
    bool computePointsAvailable() const;

    // Why nothing is drawn (no OpenGL 3.3, a shader failed); empty when all is well.
    QString glErrorString() const;

signals:
    void frameRendered(const omicron::FrameStats& stats);
    void renderSettingsChanged(const omicron::RenderSettings& settings);
    void flyModeChanged(bool on);
    void pointHovered(const omicron::PickedPoint& point);
    void hoverLeftCloud();
    // A measurement was added, removed or finished, or a point was added to the one taken.
    void measurementsChanged();

protected:
    void initializeGL() override;
    void paintGL() override;
    void mousePressEvent(QMouseEvent* event) override;
    void mouseReleaseEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void mouseDoubleClickEvent(QMouseEvent* event) override;
    void leaveEvent(QEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;
    void keyReleaseEvent(QKeyEvent* event) override;

private:
    FrameStats renderFrame(unsigned framebuffer, int widthPx, int heightPx, bool settle);

    std::unique_ptr<CloudViewPrivate> d;
};

} // namespace omicron
