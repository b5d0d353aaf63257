// MainWindow: the desktop application's window (form ui/mainwindow.ui). CloudView in the
// centre, dockable panels (build parameters, cut progress, live charts), menus, drag and
// drop, a status bar; geometry, docks, recent files and parameters persist in QSettings.
// Every long job runs in the BuilderService; failures come back as its failed() signal and
// are shown in a window-modal dialog (objectName "errorDialog") while the view is kept.
#pragma once

#include "pipeline/build_pipeline.hpp"
#include "view_parameters.hpp"

#include <QElapsedTimer>
#include <QMainWindow>
#include <QStringList>
#include <QTimer>
#include <memory>
#include <utility>
#include <vector>

class QLabel;
class QMenu;
class QMessageBox;
class QProgressBar;

namespace Ui {
class MainWindow;
}

namespace omicron {

class BuilderService;
class BuildPanel;
class ChartsPanel;
class ClassesPanel;
class MeasurementsPanel;
class ClipPanel;
class CloudView;
class CutPanel;

// The status bar's text for the point under the cursor: "x … y … z … · RGB … · class 2 Ground
// · return 1/3 · GPS time … · level …".
QString pickedPointText(const PickedPoint& point);

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    static constexpr int kMaxRecentFiles = 10;

    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    BuilderService* service() const { return m_service; }
    BuildPanel* buildPanel() const { return m_buildPanel; }
    CutPanel* cutPanel() const { return m_cutPanel; }
    ChartsPanel* chartsPanel() const { return m_chartsPanel; }
    MeasurementsPanel* measurementsPanel() const { return m_measurementsPanel; }
    ClipPanel* clipPanel() const { return m_clipPanel; }
    ClassesPanel* classesPanel() const { return m_classesPanel; }
    // The central CloudView.
    CloudView* cloudView() const { return m_view; }
    QStringList recentFiles() const { return m_recentFiles; }
    // The error dialog currently shown (nullptr when none).
    QMessageBox* errorDialog() const;
    // The first start's dock layout for a window of `window`'s size: the cut panel wide enough
    // for all level columns, the charts 45 % of the height.
    void applyDefaultDockSizes(QSize window);

    // Named viewpoints (camera pose and projection) kept with the open file's path in the
    // settings (View → Viewpoints).
    QStringList viewpointNames() const;
    void saveViewpoint(const QString& name);
    bool restoreViewpoint(const QString& name);
    void deleteViewpoint(const QString& name);

public slots:
    // What File -> Open does after its dialog: pipeline 1 (PLY/LAS/LAZ/XYZ), 2 (.oms) or 3 (.omh).
    void openFile(const QString& path);
    void openDefaultScene(quint64 points = kDefaultScenePoints);
    void saveHierarchy(const QString& path);
    void exportSortedStream(const QString& path);
    void exportPoints(const QString& path);
    // File -> Export Potree…: the hierarchy as a Potree 2.0 folder, on the service's worker,
    // with the status bar's progress bar; Cancel stops it and leaves no folder.
    void exportPotree(const QString& folder);
    // At `size` (empty: the view's own), rendered at that resolution.
    bool saveScreenshot(const QString& path, QSize size = {});
    void showError(const QString& path, const QString& message);

protected:
    void closeEvent(QCloseEvent* event) override;
    void dragEnterEvent(QDragEnterEvent* event) override;
    void dropEvent(QDropEvent* event) override;

private:
    QWidget* createCentralView();
    void createDocks();
    void connectActions();
    void connectService();
    void loadSettings();
    void createMeasureTools();
    void updateViewpointMenu();
    void saveSettings() const;
    void addRecentFile(const QString& path);
    void updateRecentMenu();
    void updateActions();
    void updateStatus();
    void applyViewParameters(const ViewParameters& parameters);
    void setColorMode(ColorMode mode);
    void showCloud(std::shared_ptr<const Hierarchy> hierarchy);
    void colorByClassesWhenClassified();
    void showShortcuts();
    void showAbout();
    QString askSavePath(const QString& title, const QString& filter, const QString& suffix);

    std::unique_ptr<Ui::MainWindow> m_ui;
    // View > Render Mode: each action and the mode it selects.
    std::vector<std::pair<QAction*, RenderMode>> m_renderModeActions;
    // View > Colour Mode: each action and the mode it selects.
    std::vector<std::pair<QAction*, ColorMode>> m_colorModeActions;
    // The user picked a colour mode: clouds opened later keep it. Until then a cloud opens in
    // RGB, or in classification once its points show classes beyond 0-2 (m_autoColorPending).
    bool m_userChoseColor = false;
    bool m_autoColorPending = false;
    std::weak_ptr<const SortedCloud> m_shownCloud; // a rebuild keeps it, an open replaces it
    BuilderService* m_service = nullptr;
    CloudView* m_view = nullptr;
    BuildPanel* m_buildPanel = nullptr;
    CutPanel* m_cutPanel = nullptr;
    ChartsPanel* m_chartsPanel = nullptr;
    MeasurementsPanel* m_measurementsPanel = nullptr;
    ClipPanel* m_clipPanel = nullptr;
    ClassesPanel* m_classesPanel = nullptr;
    QStringList m_recentFiles;
    QString m_title;         // what is shown: file name or "generated scene"
    QString m_viewpointFile; // whose viewpoints the menu lists (absolute path; empty: a scene)
    QMenu* m_viewpointMenu = nullptr;
    PipelineProgress m_progress;
    QLabel* m_phaseLabel = nullptr;
    QLabel* m_pointsLabel = nullptr;
    QLabel* m_fpsLabel = nullptr;
    QLabel* m_memoryLabel = nullptr;
    QLabel* m_pickLabel = nullptr; // the point under the cursor
    QProgressBar* m_progressBar = nullptr;
    QTimer m_statusTimer;
    std::size_t m_pointsDrawn = 0;
    FrameStats m_lastFrameStats; // the paged-points figures of the last frame
    QElapsedTimer m_lastFrame;   // since the view's last frame
};

} // namespace omicron
