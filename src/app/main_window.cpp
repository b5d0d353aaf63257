#include "main_window.hpp"

#include "build/hierarchy.hpp"
#include "build_panel.hpp"
#include "builder_service.hpp"
#include "charts_panel.hpp"
#include "class_model.hpp"
#include "classes_panel.hpp"
#include "clip_panel.hpp"
#include "cloud_view.hpp"
#include "cut_panel.hpp"
#include "measurements_panel.hpp"
#include "memory_budget.hpp"
#include "ui_mainwindow.h"

#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QGuiApplication>
#include <QImage>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QLocale>
#include <QMessageBox>
#include <QMimeData>
#include <QProgressBar>
#include <QScreen>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QToolBar>
#include <QUrl>

namespace omicron {

namespace {} // namespace

QString pickedPointText(const PickedPoint& point) {
    QString text = QStringLiteral("x %1  y %2  z %3")
                       .arg(point.source.x, 0, 'f', 3)
                       .arg(point.source.y, 0, 'f', 3)
                       .arg(point.source.z, 0, 'f', 3);
    if (point.hasColor) {
        text += QStringLiteral(" · RGB %1 %2 %3")
                    .arg(point.color.r)
                    .arg(point.color.g)
                    .arg(point.color.b);
    }
    if (point.hasIntensity) {
        text += QStringLiteral(" · intensity %1").arg(point.intensity);
    }
    if (point.hasLas) {
        text += QStringLiteral(" · class %1 %2")
                    .arg(point.classification)
                    .arg(QString::fromStdString(lasClassName(point.classification)));
        if (point.returnNumber > 0) {
            text += QStringLiteral(" · return %1/%2")
                        .arg(point.returnNumber)
                        .arg(point.numberOfReturns);
        }
        if (point.hasGpsTime) {
            text += QStringLiteral(" · GPS time %1").arg(point.gpsTime, 0, 'f', 6);
        }
    }
    return text + QStringLiteral(" · level %1").arg(point.level);
}

namespace {

QString mib(std::size_t bytes) {
    return QString::number(static_cast<double>(bytes) / 1048576.0, 'f', 0) + QStringLiteral(" MiB");
}

} // namespace

MainWindow::MainWindow(QWidget* parent)
    : QMainWindow(parent), m_ui(std::make_unique<Ui::MainWindow>()),
      m_service(new BuilderService(this)) {
    m_ui->setupUi(this);
    setCentralWidget(createCentralView());
    createDocks();

    m_phaseLabel = new QLabel(this);
    m_pointsLabel = new QLabel(this);
    m_fpsLabel = new QLabel(this);
    m_fpsLabel->setObjectName(QStringLiteral("fpsLabel"));
    m_memoryLabel = new QLabel(this);
    m_pickLabel = new QLabel(this);
    m_pickLabel->setObjectName(QStringLiteral("pickLabel"));
    m_pickLabel->setToolTip(tr("The point under the cursor: its coordinates in the file's units "
                               "(offsets included), colour, intensity and the level of the node "
                               "that draws it"));
    m_progressBar = new QProgressBar(this);
    m_progressBar->setMaximum(1000);
    m_progressBar->setMaximumWidth(160);
    m_progressBar->setTextVisible(false);
    m_progressBar->hide();
    m_phaseLabel->setToolTip(tr("Build phase"));
    m_pointsLabel->setToolTip(tr("Points drawn in the last frame / points of the cloud"));
    m_fpsLabel->setToolTip(tr("Frames per second while the view draws; \"idle\" when nothing "
                              "changed (frames are drawn on demand)"));
    m_memoryLabel->setToolTip(tr("Resident memory of the process; for a saved hierarchy larger "
                                 "than the memory budget, also the points paged in of the budget"));
    statusBar()->addPermanentWidget(m_pickLabel);
    statusBar()->addPermanentWidget(m_progressBar);
    statusBar()->addPermanentWidget(m_phaseLabel);
    statusBar()->addPermanentWidget(m_pointsLabel);
    statusBar()->addPermanentWidget(m_fpsLabel);
    statusBar()->addPermanentWidget(m_memoryLabel);

    connectActions();
    connectService();
    loadSettings();
    updateRecentMenu();
    updateActions();
    // Memory and fps change without a build: refresh the status bar twice a second.
    m_statusTimer.setInterval(500);
    connect(&m_statusTimer, &QTimer::timeout, this, &MainWindow::updateStatus);
    m_statusTimer.start();
    updateStatus();
}

MainWindow::~MainWindow() {
    // The service's worker may still post to it: stop it before the panels go.
    m_service->shutdown();
}

// The one place the central widget is made: CloudView where the widget library is built.
QWidget* MainWindow::createCentralView() {
    m_view = new CloudView(this);
    m_view->setObjectName(QStringLiteral("cloudView"));
    m_view->setMinimumSize(320, 240);
    return m_view;
}

void MainWindow::createDocks() {
    const auto dock = [this](QWidget* panel, const QString& title, const QString& name,
                             Qt::DockWidgetArea area) {
        auto* widget = new QDockWidget(title, this);
        widget->setObjectName(name); // saveState() keys docks by object name
        // In a scroll area: a panel's form never makes the window taller than the screen.
        auto* scroll = new QScrollArea(widget);
        scroll->setWidgetResizable(true);
        scroll->setFrameShape(QFrame::NoFrame);
        scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff); // as wide as the panel
        scroll->setWidget(panel);
        scroll->setMinimumWidth(panel->minimumSizeHint().width() +
                                scroll->verticalScrollBar()->sizeHint().width());
        widget->setWidget(scroll);
        addDockWidget(area, widget);
        QAction* toggle = widget->toggleViewAction();
        m_ui->menuPanels->addAction(toggle);
        return widget;
    };
    // The cut panel (progress, level table, hierarchy tree) runs the full height on the right.
    setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);
    setCorner(Qt::TopRightCorner, Qt::RightDockWidgetArea);
    m_buildPanel = new BuildPanel(this);
    m_cutPanel = new CutPanel(this);
    m_chartsPanel = new ChartsPanel(this);
    dock(m_buildPanel, tr("Build"), QStringLiteral("buildDock"), Qt::LeftDockWidgetArea);
    dock(m_cutPanel, tr("Cut progress"), QStringLiteral("cutDock"), Qt::RightDockWidgetArea);
    dock(m_chartsPanel, tr("Charts"), QStringLiteral("chartsDock"), Qt::BottomDockWidgetArea);
    m_clipPanel = new ClipPanel(this);
    QDockWidget* clipping =
        dock(m_clipPanel, tr("Clipping"), QStringLiteral("clipDock"), Qt::LeftDockWidgetArea);
    tabifyDockWidget(findChild<QDockWidget*>(QStringLiteral("buildDock")), clipping);
    findChild<QDockWidget*>(QStringLiteral("buildDock"))->raise();
    m_measurementsPanel = new MeasurementsPanel(this);
    QDockWidget* measurements = dock(m_measurementsPanel, tr("Measurements"),
                                     QStringLiteral("measurementsDock"), Qt::BottomDockWidgetArea);
    tabifyDockWidget(findChild<QDockWidget*>(QStringLiteral("chartsDock")), measurements);
    findChild<QDockWidget*>(QStringLiteral("chartsDock"))->raise();
    // Tabbed with the build panel, brought to the front when the view colours by class (the
    // legend is then what the colours mean).
    m_classesPanel = new ClassesPanel(this);
    QDockWidget* classes =
        dock(m_classesPanel, tr("Classes"), QStringLiteral("classesDock"), Qt::LeftDockWidgetArea);
    tabifyDockWidget(clipping, classes);
    findChild<QDockWidget*>(QStringLiteral("buildDock"))->raise();
    m_ui->menuPanels->actions().at(0)->setShortcut(QKeySequence(tr("Ctrl+Shift+B")));
    m_ui->menuPanels->actions().at(1)->setShortcut(QKeySequence(tr("Ctrl+Shift+U")));
    m_ui->menuPanels->actions().at(2)->setShortcut(QKeySequence(tr("Ctrl+Shift+C")));
}

void MainWindow::connectActions() {
    connect(m_ui->actionOpen, &QAction::triggered, this, [this] {
        const QString path = QFileDialog::getOpenFileName(
            this, tr("Open"), m_recentFiles.value(0),
            tr("Point clouds and hierarchies (*.ply *.las *.laz *.xyz *.pts *.txt *.csv *.oms "
               "*.omh);;"
               "Point clouds (*.ply *.las *.laz *.xyz *.pts *.txt *.csv);;"
               "Sorted streams (*.oms);;Hierarchies (*.omh);;All files (*)"));
        if (!path.isEmpty()) {
            openFile(path);
        }
    });
    connect(m_ui->actionOpenDefaultScene, &QAction::triggered, this,
            [this] { openDefaultScene(); });
    connect(m_ui->actionSaveHierarchy, &QAction::triggered, this, [this] {
        const QString path = askSavePath(tr("Save Hierarchy As"), tr("Hierarchies (*.omh)"), "omh");
        if (!path.isEmpty()) {
            saveHierarchy(path);
        }
    });
    connect(m_ui->actionExportSortedStream, &QAction::triggered, this, [this] {
        const QString path =
            askSavePath(tr("Export Sorted Stream"), tr("Sorted streams (*.oms)"), "oms");
        if (!path.isEmpty()) {
            exportSortedStream(path);
        }
    });
    connect(m_ui->actionExportPoints, &QAction::triggered, this, [this] {
        const QString path =
            askSavePath(tr("Export Points"), tr("PLY (*.ply);;LAS (*.las)"), "ply");
        if (!path.isEmpty()) {
            exportPoints(path);
        }
    });
    connect(m_ui->actionExportPotree, &QAction::triggered, this, [this] {
        // A folder to create (or an earlier export to replace): typed as a save target.
        const QString folder =
            askSavePath(tr("Export Potree Folder"), tr("Potree 2.0 folders (*)"), QString());
        if (!folder.isEmpty()) {
            exportPotree(folder);
        }
    });
    connect(m_ui->actionSaveScreenshot, &QAction::triggered, this, [this] {
        const QString path = askSavePath(tr("Save Screenshot"), tr("PNG images (*.png)"), "png");
        if (path.isEmpty()) {
            return;
        }
        // The resolution: the view's, a multiple of it, or a print/video size.
        const QSize view = m_view->size() * m_view->devicePixelRatio();
        const QList<QSize> sizes = {
            view, view * 2, view * 4, QSize(1920, 1080), QSize(3840, 2160), QSize(7680, 4320)};
        QStringList choices;
        for (int i = 0; i < sizes.size(); ++i) {
            const QString size =
                QStringLiteral("%1 × %2").arg(sizes[i].width()).arg(sizes[i].height());
            choices.append(i == 0  ? tr("%1 (the view)").arg(size)
                           : i < 3 ? tr("%1 (%2× the view)").arg(size).arg(i == 1 ? 2 : 4)
                                   : size);
        }
        bool ok = false;
        const QString choice = QInputDialog::getItem(
            this, tr("Screenshot Resolution"), tr("Size of the image:"), choices, 0, false, &ok);
        if (!ok) {
            return;
        }
        const QSize size = sizes.value(static_cast<int>(choices.indexOf(choice)), view);
        if (!saveScreenshot(path, size)) {
            showError(path, tr("%1: cannot write the screenshot (%2 × %3)")
                                .arg(path)
                                .arg(size.width())
                                .arg(size.height()));
        }
    });
    connect(m_ui->actionClearRecent, &QAction::triggered, this, [this] {
        m_recentFiles.clear();
        updateRecentMenu();
    });
    connect(m_ui->actionQuit, &QAction::triggered, this, &QWidget::close);
    connect(m_ui->actionRebuild, &QAction::triggered, m_buildPanel, &BuildPanel::requestRebuild);
    connect(m_ui->actionCancel, &QAction::triggered, m_service, &BuilderService::cancel);
    connect(m_ui->actionShortcuts, &QAction::triggered, this, &MainWindow::showShortcuts);
    connect(m_ui->actionAbout, &QAction::triggered, this, &MainWindow::showAbout);

    connect(m_buildPanel, &BuildPanel::rebuildRequested, this, [this](const BuildOptions& options) {
        m_service->setOptions(m_buildPanel->pipelineOptions());
        m_service->rebuild(options);
    });
    connect(m_buildPanel, &BuildPanel::cancelRequested, m_service, &BuilderService::cancel);
    connect(m_buildPanel, &BuildPanel::viewParametersChanged, this,
            &MainWindow::applyViewParameters);
    connect(m_chartsPanel, &ChartsPanel::exportFailed, this, &MainWindow::showError);
    // The node selected in the cut panel's hierarchy tree is drawn as a box in the view.
    connect(m_cutPanel, &CutPanel::nodeSelected, m_view,
            [this](int level, quint64 code) { m_view->setHighlightedNode(level, code); });
    connect(m_cutPanel, &CutPanel::nodeSelectionCleared, m_view, &CloudView::clearHighlightedNode);

    auto* renderModes = new QActionGroup(this);
    m_renderModeActions = {{m_ui->actionComputePoints, RenderMode::ComputePoints},
                           {m_ui->actionPoints, RenderMode::Points},
                           {m_ui->actionSplats, RenderMode::Splats}};
    for (const auto& [action, mode] : m_renderModeActions) {
        renderModes->addAction(action);
        action->setChecked(mode == ViewParameters{}.renderMode);
        connect(action, &QAction::triggered, this, [this, mode = mode] {
            ViewParameters parameters = m_buildPanel->viewParameters();
            parameters.renderMode = mode;
            m_buildPanel->setViewParameters(parameters);
        });
    }
    auto* colorModes = new QActionGroup(this);
    for (QAction* action : m_ui->menuColorMode->actions()) {
        if (!action->isSeparator()) {
            colorModes->addAction(action);
        }
    }
    m_ui->actionColorRgb->setChecked(true);
    m_ui->actionShowCutBoundary->setChecked(true);
    m_ui->actionShowAxes->setChecked(true);

    const auto editSettings = [this](auto&& edit) {
        RenderSettings settings = m_view->renderSettings();
        edit(settings);
        m_view->setRenderSettings(settings);
    };
    m_colorModeActions = {{m_ui->actionColorRgb, ColorMode::Rgb},
                          {m_ui->actionColorNormal, ColorMode::Normal},
                          {m_ui->actionColorHeight, ColorMode::Height},
                          {m_ui->actionColorIntensity, ColorMode::Intensity},
                          {m_ui->actionColorLevel, ColorMode::Level},
                          {m_ui->actionColorBuildAge, ColorMode::BuildAge},
                          {m_ui->actionColorClassification, ColorMode::Classification},
                          {m_ui->actionColorReturnNumber, ColorMode::ReturnNumber},
                          {m_ui->actionColorGpsTime, ColorMode::GpsTime}};
    for (const auto& [action, mode] : m_colorModeActions) {
        connect(action, &QAction::triggered, this, [this, mode = mode] {
            m_userChoseColor = true; // from now on, no cloud changes it
            m_autoColorPending = false;
            setColorMode(mode);
        });
    }
    // The Classes dock: its check boxes edit the view's hidden classes, which it shows.
    connect(m_classesPanel, &ClassesPanel::classVisibilityChanged, m_view,
            &CloudView::setClassVisible);
    connect(m_classesPanel, &ClassesPanel::allClassesHidden, this, [this, editSettings](bool hide) {
        editSettings([&](RenderSettings& s) {
            for (const int classification : m_classesPanel->model()->classes()) {
                s.hiddenClasses.set(static_cast<std::size_t>(classification), hide);
            }
        });
    });
    connect(m_view, &CloudView::renderSettingsChanged, this, [this](const RenderSettings& s) {
        m_classesPanel->setHiddenClasses(s.hiddenClasses);
        for (const auto& [action, mode] : m_colorModeActions) {
            if (mode == s.color) {
                action->setChecked(true);
            }
        }
    });
    connect(m_classesPanel, &ClassesPanel::countsChanged, this,
            &MainWindow::colorByClassesWhenClassified);
    connect(m_ui->actionPointSizeLarger, &QAction::triggered, this, [editSettings] {
        editSettings([](RenderSettings& s) {
            s.pointSizeScale = std::min(16.0f, s.pointSizeScale * 1.25f);
        });
    });
    connect(m_ui->actionPointSizeSmaller, &QAction::triggered, this, [editSettings] {
        editSettings(
            [](RenderSettings& s) { s.pointSizeScale = std::max(0.1f, s.pointSizeScale / 1.25f); });
    });
    connect(m_ui->actionPointSizeReset, &QAction::triggered, this,
            [editSettings] { editSettings([](RenderSettings& s) { s.pointSizeScale = 1.0f; }); });
    connect(m_ui->actionShowOctreeCells, &QAction::toggled, this, [editSettings](bool on) {
        editSettings([on](RenderSettings& s) { s.showOctreeCells = on; });
    });
    connect(m_ui->actionShowCutBoundary, &QAction::toggled, this, [editSettings](bool on) {
        editSettings([on](RenderSettings& s) { s.showCutBoundary = on; });
    });
    connect(m_ui->actionShowAxes, &QAction::toggled, this, [editSettings](bool on) {
        editSettings([on](RenderSettings& s) { s.showAxes = on; });
    });
    connect(m_ui->actionFit, &QAction::triggered, m_view, &CloudView::fitToCloud);
    const std::pair<QAction*, StandardView> views[] = {
        {m_ui->actionViewTop, StandardView::Top},
        {m_ui->actionViewBottom, StandardView::Bottom},
        {m_ui->actionViewFront, StandardView::Front},
        {m_ui->actionViewBack, StandardView::Back},
        {m_ui->actionViewLeft, StandardView::Left},
        {m_ui->actionViewRight, StandardView::Right},
        {m_ui->actionViewIso, StandardView::Iso}};
    for (const auto& [action, standard] : views) {
        connect(action, &QAction::triggered, m_view,
                [this, standard = standard] { m_view->setStandardView(standard); });
    }
    connect(m_ui->actionFlyMode, &QAction::toggled, m_view, &CloudView::setFlyMode);
    connect(m_view, &CloudView::flyModeChanged, m_ui->actionFlyMode, &QAction::setChecked);
    createMeasureTools();
    // View → Orthographic Projection: sections and facades without perspective.
    QAction* orthographic = new QAction(tr("&Orthographic Projection"), this);
    orthographic->setObjectName(QStringLiteral("actionOrthographic"));
    orthographic->setCheckable(true);
    orthographic->setShortcut(QKeySequence(tr("O")));
    orthographic->setStatusTip(tr("Parallel projection: parallel lines stay parallel (sections, "
                                  "facades, plans); O switches back"));
    m_ui->menuView->insertAction(m_ui->actionFlyMode, orthographic);
    // View → Viewpoints: named cameras kept per file.
    m_viewpointMenu = new QMenu(tr("View&points"), this);
    m_ui->menuView->insertMenu(m_ui->actionFlyMode, m_viewpointMenu);
    updateViewpointMenu();
    connect(orthographic, &QAction::toggled, m_view, &CloudView::setOrthographic);
    m_view->setHoverPicking(true);
    connect(m_view, &CloudView::pointHovered, this, [this](const PickedPoint& point) {
        m_pickLabel->setText(pickedPointText(point));
        m_clipPanel->setPickedPoint(point.source);
    });
    connect(m_clipPanel, &ClipPanel::clipChanged, this, [this](const std::optional<ClipBox>& clip) {
        RenderSettings settings = m_view->renderSettings();
        settings.clip = clip;
        m_view->setRenderSettings(settings);
    });
    connect(m_view, &CloudView::hoverLeftCloud, m_pickLabel, &QLabel::clear);
    connect(m_view, &CloudView::frameRendered, this, [this](const FrameStats& stats) {
        m_chartsPanel->setFrame(stats);
        m_cutPanel->setFrontNodes(stats.frontNodesPerLevel);
        m_pointsDrawn = stats.pointsDrawn;
        m_lastFrameStats = stats;
        m_lastFrame.start();
    });
}

void MainWindow::createMeasureTools() {
    // The Measure menu and toolbar: one tool at a time, Navigate for none (M: distance).
    QMenu* menu = new QMenu(tr("&Measure"), this);
    menuBar()->insertMenu(m_ui->menuHelp->menuAction(), menu);
    QToolBar* toolbar = addToolBar(tr("Measure"));
    toolbar->setObjectName(QStringLiteral("measureToolbar"));
    auto* group = new QActionGroup(this);
    const auto tool = [&](const QString& text, const QString& name, std::optional<MeasureKind> kind,
                          const QKeySequence& shortcut, const QString& tip) {
        QAction* action = menu->addAction(text);
        action->setObjectName(name);
        action->setCheckable(true);
        action->setShortcut(shortcut);
        action->setToolTip(tip);
        group->addAction(action);
        toolbar->addAction(action);
        connect(action, &QAction::triggered, this, [this, kind] {
            m_view->setMeasureTool(kind);
            if (kind) {
                statusBar()->showMessage(
                    tr("Measuring: click points on the cloud%1; Esc drops the unfinished one")
                        .arg(Measurement::fixedPoints(*kind) == 0
                                 ? tr(", double-click or Enter to finish")
                                 : QString()),
                    8000);
            }
        });
        return action;
    };
    tool(tr("&Navigate"), QStringLiteral("actionNavigate"), std::nullopt, QKeySequence(tr("N")),
         tr("Orbit, pan and zoom; clicks measure nothing"))
        ->setChecked(true);
    tool(tr("&Distance"), QStringLiteral("actionMeasureDistance"), MeasureKind::Distance,
         QKeySequence(tr("M")), tr("Distance between two picked points"));
    tool(tr("&Height Difference"), QStringLiteral("actionMeasureHeight"), MeasureKind::Height,
         QKeySequence(), tr("Height of the second picked point above the first"));
    tool(tr("&Polyline Length"), QStringLiteral("actionMeasurePolyline"), MeasureKind::Polyline,
         QKeySequence(), tr("Length of a polyline through picked points"));
    tool(tr("Horizontal &Area"), QStringLiteral("actionMeasureArea"), MeasureKind::Area,
         QKeySequence(),
         tr("Area of the polygon through picked points, projected on the "
            "horizontal plane"));
    menu->addSeparator();
    QAction* clear = menu->addAction(tr("&Clear Measurements"));
    connect(clear, &QAction::triggered, m_view, &CloudView::clearMeasurements);
    connect(m_view, &CloudView::measurementsChanged, this,
            [this] { m_measurementsPanel->setMeasurements(m_view->measurements()); });
    connect(m_measurementsPanel, &MeasurementsPanel::removeRequested, this,
            [this](const std::vector<std::size_t>& indices) {
                for (const std::size_t index : indices) { // descending: indices stay valid
                    m_view->removeMeasurement(index);
                }
            });
    connect(m_measurementsPanel, &MeasurementsPanel::clearRequested, m_view,
            &CloudView::clearMeasurements);
    connect(m_measurementsPanel, &MeasurementsPanel::exportFailed, this, &MainWindow::showError);
}

void MainWindow::connectService() {
    connect(m_service, &BuilderService::buildStarted, this, [this](const QString& title) {
        m_title = title;
        setWindowTitle(tr("%1 — omicron").arg(title));
        m_chartsPanel->startBuild();
        m_chartsPanel->setMemoryBudget(m_buildPanel->pipelineOptions().memoryBudgetBytes);
        m_progressBar->setValue(0);
        m_progressBar->show();
    });
    connect(m_service, &BuilderService::progressChanged, this,
            [this](const PipelineProgress& progress) {
                m_progress = progress;
                m_cutPanel->setProgress(progress);
                m_chartsPanel->setProgress(progress);
                if (progress.scanningBounds()) {
                    m_progressBar->setValue(
                        static_cast<int>(1000.0 * progress.bytesScanned / progress.bytesToScan));
                } else {
                    // Read, sort and insert each take a third of the bar.
                    const double total = std::max<double>(1.0, double(progress.pointsTotal));
                    m_progressBar->setValue(static_cast<int>(
                        1000.0 *
                        (progress.pointsRead + progress.pointsSorted + progress.pointsInserted) /
                        (3.0 * total)));
                }
                updateStatus();
            });
    connect(m_service, &BuilderService::statisticsChanged, this,
            [this](const BuildStatistics& statistics) {
                m_cutPanel->setStatistics(statistics);
                m_chartsPanel->setHierarchyBytes(statistics.bytesResident());
            });
    connect(m_service, &BuilderService::hierarchyChanged, this,
            [this](std::shared_ptr<const Hierarchy> hierarchy) {
                m_cutPanel->setHierarchy(hierarchy);
                if (hierarchy != nullptr) {
                    const CubeTransform& cube = hierarchy->cloud().cube();
                    m_clipPanel->setCloudBounds(cube.origin, cube.origin + glm::dvec3(cube.edge));
                }
                showCloud(std::move(hierarchy));
            });
    connect(m_service, &BuilderService::previewChanged, this,
            [this](const PreviewSample& preview, const CubeTransform& cube) {
                m_view->setPreview(preview, cube);
            });
    connect(m_service, &BuilderService::buildFinished, this, [this](const PipelineResult& result) {
        const QLocale locale;
        const auto kept = m_service->source();
        if (result.cancelled && kept && kept->path != result.source.path) {
            // Cancelled before the new file replaced anything (its bounds pre-pass): the view
            // still shows the previous cloud, so does the title.
            const QString previous = m_title;
            m_title = m_service->sourceTitle();
            setWindowTitle(tr("%1 — omicron").arg(m_title));
            statusBar()->showMessage(tr("Opening %1 cancelled").arg(previous), 10000);
            return;
        }
        statusBar()->showMessage(
            result.cancelled ? tr("Build of %1 cancelled").arg(m_title)
                             : tr("%1: %2 points, %3 nodes in %4 s")
                                   .arg(m_title, locale.toString(quint64(result.stats.inputPoints)),
                                        locale.toString(quint64(result.stats.totalNodes())))
                                   .arg(result.stats.creationSeconds, 0, 'f', 2),
            10000);
    });
    connect(m_service, &BuilderService::jobFinished, this,
            [this](const QString& message) { statusBar()->showMessage(message, 10000); });
    connect(m_service, &BuilderService::jobProgressChanged, this,
            [this](quint64 done, quint64 total) {
                m_progressBar->setValue(static_cast<int>(1000.0 * double(done) / double(total)));
            });
    connect(m_service, &BuilderService::failed, this, &MainWindow::showError);
    connect(m_service, &BuilderService::busyChanged, this, [this](bool busy) {
        m_buildPanel->setBusy(busy);
        m_progressBar->setVisible(busy);
        updateActions();
    });
}

void MainWindow::openFile(const QString& path) {
    const QFileInfo info(path);
    m_viewpointFile = info.absoluteFilePath();
    updateViewpointMenu();
    // A .omh takes the memory budget only: beyond it, its points are paged in on demand.
    m_service->setOptions(m_buildPanel->pipelineOptions());
    if (info.suffix().compare(QStringLiteral("omh"), Qt::CaseInsensitive) == 0) {
        m_service->openHierarchy(path);
    } else {
        m_service->open(path);
    }
    addRecentFile(info.absoluteFilePath());
}

namespace {

// Where a file's viewpoints are kept: one settings group per file path.
QString viewpointKey(const QString& file) {
    return QStringLiteral("viewpoints/") + QString::fromLatin1(QUrl::toPercentEncoding(
                                               file.isEmpty() ? QStringLiteral("-") : file));
}

} // namespace

QStringList MainWindow::viewpointNames() const {
    QStringList names = QSettings().value(viewpointKey(m_viewpointFile)).toMap().keys();
    names.sort(Qt::CaseInsensitive);
    return names;
}

void MainWindow::saveViewpoint(const QString& name) {
    if (name.trimmed().isEmpty()) {
        return;
    }
    const ViewCamera camera = m_view->camera();
    const glm::dvec3 pivot = camera.pivot();
    QSettings settings;
    QVariantMap all = settings.value(viewpointKey(m_viewpointFile)).toMap();
    all.insert(name.trimmed(),
               QVariantList{pivot.x, pivot.y, pivot.z, camera.distance(), camera.yawRadians(),
                            camera.pitchRadians(), camera.orthographic()});
    settings.setValue(viewpointKey(m_viewpointFile), all);
    updateViewpointMenu();
}

bool MainWindow::restoreViewpoint(const QString& name) {
    const QVariantList values =
        QSettings().value(viewpointKey(m_viewpointFile)).toMap().value(name).toList();
    if (values.size() != 7) {
        return false;
    }
    ViewCamera camera = m_view->camera();
    camera.setPose(glm::dvec3(values[0].toDouble(), values[1].toDouble(), values[2].toDouble()),
                   values[3].toDouble(), values[4].toDouble(), values[5].toDouble());
    camera.setOrthographic(values[6].toBool());
    m_view->setCamera(camera);
    if (auto* orthographic = findChild<QAction*>(QStringLiteral("actionOrthographic"))) {
        orthographic->setChecked(camera.orthographic());
    }
    return true;
}

void MainWindow::deleteViewpoint(const QString& name) {
    QSettings settings;
    QVariantMap all = settings.value(viewpointKey(m_viewpointFile)).toMap();
    all.remove(name);
    settings.setValue(viewpointKey(m_viewpointFile), all);
    updateViewpointMenu();
}

void MainWindow::updateViewpointMenu() {
    if (m_viewpointMenu == nullptr) {
        return;
    }
    m_viewpointMenu->clear();
    QAction* save = m_viewpointMenu->addAction(tr("&Save Viewpoint…"));
    save->setShortcut(QKeySequence(tr("Ctrl+Shift+V")));
    connect(save, &QAction::triggered, this, [this] {
        bool ok = false;
        const QString name = QInputDialog::getText(
            this, tr("Save Viewpoint"),
            tr("Name of this viewpoint (kept with %1):")
                .arg(m_viewpointFile.isEmpty() ? tr("the generated scene")
                                               : QFileInfo(m_viewpointFile).fileName()),
            QLineEdit::Normal, QString(), &ok);
        if (ok) {
            saveViewpoint(name);
        }
    });
    const QStringList names = viewpointNames();
    if (!names.isEmpty()) {
        m_viewpointMenu->addSeparator();
    }
    QMenu* remove = names.isEmpty() ? nullptr : new QMenu(tr("&Delete"), m_viewpointMenu);
    for (const QString& name : names) {
        connect(m_viewpointMenu->addAction(name), &QAction::triggered, this,
                [this, name] { restoreViewpoint(name); });
        connect(remove->addAction(name), &QAction::triggered, this,
                [this, name] { deleteViewpoint(name); });
    }
    if (remove != nullptr) {
        m_viewpointMenu->addSeparator();
        m_viewpointMenu->addMenu(remove);
    }
}

void MainWindow::openDefaultScene(quint64 points) {
    m_viewpointFile.clear();
    updateViewpointMenu();
    m_service->setOptions(m_buildPanel->pipelineOptions());
    m_service->openGeneratedScene(points, kDefaultSceneSeed);
}

void MainWindow::saveHierarchy(const QString& path) {
    m_service->saveHierarchy(path);
}

void MainWindow::exportSortedStream(const QString& path) {
    m_service->exportSortedStream(path);
}

void MainWindow::exportPoints(const QString& path) {
    // With the view clipped, what is exported is what is shown: the points in the clip box.
    m_service->exportPoints(path, m_view->renderSettings().clip);
}

void MainWindow::exportPotree(const QString& folder) {
    if (m_service->exportPotree(folder)) {
        m_progressBar->setValue(0);
        statusBar()->showMessage(tr("Exporting %1 to Potree… (Cancel: Ctrl+.)").arg(folder));
    }
}

bool MainWindow::saveScreenshot(const QString& path, QSize size) {
    if (size.isEmpty()) {
        size = m_view->size() * m_view->devicePixelRatio();
    }
    // Drawn again at that size (the front refined for it), not scaled from the screen.
    const QImage image = m_view->renderImage(size);
    return !image.isNull() && image.save(path);
}

QMessageBox* MainWindow::errorDialog() const {
    return findChild<QMessageBox*>(QStringLiteral("errorDialog"));
}

void MainWindow::showError(const QString& path, const QString& message) {
    // Window-modal and opened with open(), not exec(): the event loop (and a running build)
    // goes on, and tests can find the dialog by name and close it.
    if (QMessageBox* previous = errorDialog()) {
        previous->close();
        previous->deleteLater();
        previous->setObjectName(QString());
    }
    auto* box =
        new QMessageBox(QMessageBox::Critical, tr("omicron"),
                        path.isEmpty() ? tr("The operation failed.")
                                       : tr("Cannot use %1").arg(QFileInfo(path).fileName()),
                        QMessageBox::Ok, this);
    box->setObjectName(QStringLiteral("errorDialog"));
    box->setInformativeText(message);
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->setWindowModality(Qt::WindowModal);
    box->open();
    statusBar()->showMessage(message, 10000);
}

void MainWindow::closeEvent(QCloseEvent* event) {
    // Cancel first so the join in shutdown() waits only for the next cancellation check.
    m_service->shutdown();
    saveSettings();
    event->accept();
}

void MainWindow::dragEnterEvent(QDragEnterEvent* event) {
    if (event->mimeData()->hasUrls() && !event->mimeData()->urls().isEmpty() &&
        event->mimeData()->urls().first().isLocalFile()) {
        event->acceptProposedAction();
    }
}

void MainWindow::dropEvent(QDropEvent* event) {
    const QList<QUrl> urls = event->mimeData()->urls();
    if (!urls.isEmpty() && urls.first().isLocalFile()) {
        openFile(urls.first().toLocalFile());
        event->acceptProposedAction();
    }
}

void MainWindow::loadSettings() {
    QSettings settings;
    const bool placed = restoreGeometry(settings.value("window/geometry").toByteArray());
    if (!placed) {
        // First start: most of the screen, centred.
        const QRect screen = QGuiApplication::primaryScreen() != nullptr
                                 ? QGuiApplication::primaryScreen()->availableGeometry()
                                 : QRect(0, 0, 1280, 800);
        const QSize size(screen.width() * 9 / 10, screen.height() * 9 / 10);
        resize(size);
        move(screen.center() - QPoint(size.width() / 2, size.height() / 2));
    }
    if (!placed || !restoreState(settings.value("window/state").toByteArray())) {
        applyDefaultDockSizes(size());
    }
    m_chartsPanel->setFollowSeconds(settings.value("charts/followSeconds", 0.0).toDouble());
    m_recentFiles = settings.value("recentFiles").toStringList();
    while (m_recentFiles.size() > kMaxRecentFiles) {
        m_recentFiles.removeLast();
    }
    m_buildPanel->loadSettings(settings);
    applyViewParameters(m_buildPanel->viewParameters());
}

void MainWindow::applyDefaultDockSizes(QSize window) {
    // The cut panel wide enough for every column of its level table (never more than 45 % of
    // the window), the charts 45 % of the height (both rows of charts whole, with room for
    // their tick labels, under their tab bar): the view keeps the rest.
    const int cutWidth = std::min(m_cutPanel->widthForAllLevelColumns(), window.width() * 45 / 100);
    resizeDocks({findChild<QDockWidget*>(QStringLiteral("cutDock"))}, {cutWidth}, Qt::Horizontal);
    resizeDocks({findChild<QDockWidget*>(QStringLiteral("chartsDock"))}, {window.height() * 9 / 20},
                Qt::Vertical);
}

void MainWindow::saveSettings() const {
    QSettings settings;
    settings.setValue("window/geometry", saveGeometry());
    settings.setValue("window/state", saveState());
    settings.setValue("charts/followSeconds", m_chartsPanel->followSeconds());
    settings.setValue("recentFiles", m_recentFiles);
    m_buildPanel->saveSettings(settings);
}

void MainWindow::addRecentFile(const QString& path) {
    m_recentFiles.removeAll(path);
    m_recentFiles.prepend(path);
    while (m_recentFiles.size() > kMaxRecentFiles) {
        m_recentFiles.removeLast();
    }
    updateRecentMenu();
    QSettings().setValue("recentFiles", m_recentFiles);
}

void MainWindow::updateRecentMenu() {
    QMenu* menu = m_ui->menuOpenRecent;
    for (QAction* action : menu->actions()) {
        if (action != m_ui->actionClearRecent) {
            menu->removeAction(action);
            action->deleteLater();
        }
    }
    QAction* before = m_ui->actionClearRecent;
    for (int i = 0; i < m_recentFiles.size(); ++i) {
        const QString path = m_recentFiles.at(i);
        auto* action = new QAction(
            QStringLiteral("&%1 %2").arg((i + 1) % 10).arg(QFileInfo(path).fileName()), menu);
        action->setToolTip(path);
        action->setStatusTip(path);
        connect(action, &QAction::triggered, this, [this, path] { openFile(path); });
        menu->insertAction(before, action);
    }
    if (!m_recentFiles.isEmpty()) {
        menu->insertSeparator(before);
    }
    menu->setEnabled(!m_recentFiles.isEmpty());
}

void MainWindow::updateActions() {
    const bool busy = m_service->busy();
    m_ui->actionCancel->setEnabled(busy);
    // Exports need the whole sorted list; the service also refuses them with a message.
    const bool haveCloud = m_service->hasCompleteCloud();
    m_ui->actionExportSortedStream->setEnabled(haveCloud);
    m_ui->actionExportPoints->setEnabled(haveCloud);
    m_ui->actionExportPotree->setEnabled(m_service->hierarchy() != nullptr);
    m_ui->actionSaveHierarchy->setEnabled(m_service->hierarchy() != nullptr);
}

void MainWindow::updateStatus() {
    const QLocale locale;
    m_phaseLabel->setText(m_progress.scanningBounds()
                              ? tr("scanning bounds")
                              : QString::fromLatin1(toString(m_progress.phase)));
    // Before the source is open (an XYZ file's bounds scan) its count is not known yet.
    m_pointsLabel->setText(m_progress.pointsTotal == 0
                               ? tr("%1 points drawn").arg(locale.toString(quint64(m_pointsDrawn)))
                               : tr("%1 / %2 points")
                                     .arg(locale.toString(quint64(m_pointsDrawn)),
                                          locale.toString(quint64(m_progress.pointsTotal))));
    // The view draws on demand: with nothing changing for a while it is idle, not slow.
    constexpr qint64 kIdleMs = 1500;
    m_fpsLabel->setText(m_lastFrame.isValid() && m_lastFrame.elapsed() < kIdleMs
                            ? tr("%1 fps").arg(m_chartsPanel->frameRate(), 0, 'f', 1)
                            : tr("idle"));
    // A .omh beyond the memory budget: its points come and go with the view.
    const FrameStats& frame = m_lastFrameStats;
    const QString resident = mib(processResidentSet().bytes);
    m_memoryLabel->setText(
        frame.pagedPoints
            ? tr("%1 (points paged: %2 of %3%4)")
                  .arg(resident, mib(frame.pagedResidentBytes), mib(frame.pagedBudgetBytes),
                       frame.pendingLoads > 0 ? tr(", %1 nodes loading").arg(frame.pendingLoads)
                                              : QString())
            : resident);
}

void MainWindow::setColorMode(ColorMode mode) {
    RenderSettings settings = m_view->renderSettings();
    settings.color = mode;
    m_view->setRenderSettings(settings);
    if (mode == ColorMode::Classification) {
        findChild<QDockWidget*>(QStringLiteral("classesDock"))->raise(); // the legend
    }
}

void MainWindow::showCloud(std::shared_ptr<const Hierarchy> hierarchy) {
    const bool newCloud = hierarchy != nullptr && m_shownCloud.lock() != hierarchy->sharedCloud();
    if (newCloud) {
        m_shownCloud = hierarchy->sharedCloud();
        // Classes are a property of the cloud: every class of a new one is shown.
        RenderSettings settings = m_view->renderSettings();
        settings.hiddenClasses.reset();
        if (!m_userChoseColor) {
            settings.color = ColorMode::Rgb; // until its classes say otherwise
            m_autoColorPending = hierarchy->cloud().attributes().has(Attribute::Las);
        }
        m_view->setRenderSettings(settings);
    }
    m_classesPanel->setHierarchy(hierarchy);
    m_view->setHierarchy(std::move(hierarchy));
}

void MainWindow::colorByClassesWhenClassified() {
    if (!m_autoColorPending) {
        return;
    }
    // Classes 0-2 (never classified, unclassified, ground) come with most scans and say little;
    // any other class means someone classified the cloud, which is then what to look at.
    const ClassCounter::Snapshot& counts = m_classesPanel->counts();
    for (int classification = 3; classification < kLasClassCount; ++classification) {
        if (counts.counts[static_cast<std::size_t>(classification)] > 0) {
            m_autoColorPending = false;
            setColorMode(ColorMode::Classification);
            return;
        }
    }
    if (counts.complete || counts.notCounted) {
        m_autoColorPending = false;
    }
}

void MainWindow::applyViewParameters(const ViewParameters& parameters) {
    for (const auto& [action, mode] : m_renderModeActions) {
        action->setChecked(parameters.renderMode == mode);
    }
    RenderSettings settings = m_view->renderSettings();
    settings.projectionThresholdPx = parameters.projectionThresholdPx;
    settings.pointBudget = parameters.pointBudget;
    settings.mode = parameters.renderMode;
    settings.edl = parameters.edl;
    settings.edlStrength = parameters.edlStrength;
    settings.edlRadiusPx = parameters.edlRadiusPx;
    m_view->setRenderSettings(settings);
}

QString MainWindow::askSavePath(const QString& title, const QString& filter,
                                const QString& suffix) {
    QFileDialog dialog(this, title,
                       m_recentFiles.isEmpty() ? QString()
                                               : QFileInfo(m_recentFiles.first()).absolutePath(),
                       filter);
    dialog.setAcceptMode(QFileDialog::AcceptSave);
    dialog.setDefaultSuffix(suffix);
    return dialog.exec() == QDialog::Accepted && !dialog.selectedFiles().isEmpty()
               ? dialog.selectedFiles().first()
               : QString();
}

void MainWindow::showShortcuts() {
    QString rows;
    const auto addMenu = [&](QMenu* menu, auto&& self) -> void {
        for (QAction* action : menu->actions()) {
            if (action->menu() != nullptr) {
                self(action->menu(), self);
            } else if (!action->shortcut().isEmpty()) {
                rows +=
                    QStringLiteral("<tr><td>%1</td><td>%2</td></tr>")
                        .arg(action->shortcut().toString(QKeySequence::NativeText).toHtmlEscaped(),
                             action->text().remove(QLatin1Char('&')).toHtmlEscaped());
            }
        }
    };
    for (QMenu* menu : {m_ui->menuFile, m_ui->menuBuild, m_ui->menuView, m_ui->menuHelp}) {
        addMenu(menu, addMenu);
    }
    rows += tr("<tr><td>Left drag</td><td>Orbit</td></tr>"
               "<tr><td>Right / middle drag</td><td>Pan</td></tr>"
               "<tr><td>Wheel</td><td>Zoom</td></tr>"
               "<tr><td>Double click</td><td>Centre on the point</td></tr>"
               "<tr><td>W A S D Q E (fly mode)</td><td>Fly</td></tr>");
    auto* box = new QMessageBox(QMessageBox::Information, tr("Keyboard shortcuts"),
                                QStringLiteral("<table cellspacing=4>%1</table>").arg(rows),
                                QMessageBox::Close, this);
    box->setObjectName(QStringLiteral("shortcutsDialog"));
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->open();
}

void MainWindow::showAbout() {
    QMessageBox::about(
        this, tr("About omicron"),
        tr("<h3>omicron %1</h3><p>Look at huge point clouds while their level-of-detail octree "
           "is being built: an implementation of <i>OMiCroN — Oblique Multipass Hierarchy "
           "Creation while Navigating</i>.</p><p>Pipelines: unsorted cloud → incremental "
           "Morton sorter → parallel oblique-cut builder; sorted stream (.oms) → builder; "
           "hierarchy file (.omh).</p>")
            .arg(QApplication::applicationVersion()));
}

} // namespace omicron
