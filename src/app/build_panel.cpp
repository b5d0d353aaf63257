#include "build_panel.hpp"

#include "memory_budget.hpp"
#include "ui_buildpanel.h"

#include <QFileDialog>
#include <QSettings>
#include <algorithm>
#include <iterator>
#include <utility>

namespace omicron {

namespace {

// The render combo's items, in the order of ui/buildpanel.ui, with their settings names.
constexpr std::pair<RenderMode, const char*> kRenderModes[] = {
    {RenderMode::ComputePoints, "compute"},
    {RenderMode::Points, "points"},
    {RenderMode::Splats, "splats"},
};

// The eye-dome lighting combo's items, in the order of ui/buildpanel.ui.
constexpr std::pair<EdlMode, const char*> kEdlModes[] = {
    {EdlMode::Auto, "auto"},
    {EdlMode::On, "on"},
    {EdlMode::Off, "off"},
};

int edlModeIndex(EdlMode mode) {
    for (int i = 0; i < static_cast<int>(std::size(kEdlModes)); ++i) {
        if (kEdlModes[i].first == mode) {
            return i;
        }
    }
    return 0;
}

int renderModeIndex(RenderMode mode) {
    for (int i = 0; i < static_cast<int>(std::size(kRenderModes)); ++i) {
        if (kRenderModes[i].first == mode) {
            return i;
        }
    }
    return 0;
}

} // namespace

BuildPanel::BuildPanel(QWidget* parent)
    : QWidget(parent), m_ui(std::make_unique<Ui::BuildPanel>()) {
    m_ui->setupUi(this);
    m_ui->depthSpin->setMaximum(morton::kMaxLevel);
    m_ui->chunksSpin->setMaximum(kMaxSortChunks);
    setPipelineOptions(PipelineOptions{});
    setViewParameters(ViewParameters{});
    connect(m_ui->rebuildButton, &QPushButton::clicked, this, &BuildPanel::requestRebuild);
    connect(m_ui->cancelButton, &QPushButton::clicked, this, &BuildPanel::cancelRequested);
    connect(m_ui->tempDirButton, &QToolButton::clicked, this, [this] {
        const QString folder = QFileDialog::getExistingDirectory(
            this, tr("Scratch folder for sorted runs"), m_ui->tempDirEdit->text());
        if (!folder.isEmpty()) {
            m_ui->tempDirEdit->setText(folder);
        }
    });
    const auto viewEdited = [this] {
        emit viewParametersChanged(viewParameters());
    };
    connect(m_ui->thresholdSpin, &QDoubleSpinBox::valueChanged, this, viewEdited);
    connect(m_ui->budgetSpin, &QSpinBox::valueChanged, this, viewEdited);
    connect(m_ui->renderModeCombo, &QComboBox::currentIndexChanged, this, viewEdited);
    connect(m_ui->edlCombo, &QComboBox::currentIndexChanged, this, viewEdited);
    connect(m_ui->edlStrengthSpin, &QDoubleSpinBox::valueChanged, this, viewEdited);
    connect(m_ui->edlRadiusSpin, &QDoubleSpinBox::valueChanged, this, viewEdited);
}

BuildPanel::~BuildPanel() = default;

PipelineOptions BuildPanel::pipelineOptions() const {
    PipelineOptions options;
    options.build.maxLevel = m_ui->depthSpin->value();
    options.build.collapse = static_cast<LeafCollapse>(m_ui->collapseCombo->currentIndex());
    options.build.ratio = m_ui->ratioSpin->value();
    options.build.worklistSize = static_cast<std::size_t>(m_ui->worklistSpin->value());
    options.build.threads = m_ui->threadsSpin->value();
    options.sortChunks = m_ui->chunksSpin->value();
    options.storage = static_cast<PointStorage>(m_ui->storeCombo->currentIndex());
    // 0 is automatic; anything else at least the pipeline's minimum.
    const std::uint64_t budgetMiB = static_cast<std::uint64_t>(m_ui->memoryBudgetSpin->value());
    options.memoryBudgetBytes = budgetMiB == 0 ? 0 : std::max(budgetMiB * kMiB, kMinMemoryBudget);
    options.tempDir = m_ui->tempDirEdit->text().trimmed().toStdString();
    return options;
}

void BuildPanel::setPipelineOptions(const PipelineOptions& options) {
    m_ui->depthSpin->setValue(options.build.maxLevel);
    m_ui->collapseCombo->setCurrentIndex(static_cast<int>(options.build.collapse));
    m_ui->ratioSpin->setValue(options.build.ratio);
    m_ui->worklistSpin->setValue(static_cast<int>(options.build.worklistSize));
    m_ui->threadsSpin->setValue(options.build.threads);
    m_ui->chunksSpin->setValue(options.sortChunks);
    m_ui->storeCombo->setCurrentIndex(static_cast<int>(options.storage));
    // 0 (automatic) or whole MiB, at least the pipeline's minimum.
    const std::uint64_t budgetMiB = options.memoryBudgetBytes / kMiB;
    m_ui->memoryBudgetSpin->setValue(budgetMiB == 0 ? 0
                                                    : static_cast<int>(std::max<std::uint64_t>(
                                                          kMinMemoryBudget / kMiB, budgetMiB)));
    m_ui->tempDirEdit->setText(QString::fromStdString(options.tempDir));
}

ViewParameters BuildPanel::viewParameters() const {
    ViewParameters parameters;
    parameters.projectionThresholdPx = m_ui->thresholdSpin->value();
    parameters.pointBudget = static_cast<std::size_t>(m_ui->budgetSpin->value()) * 1000;
    const int index = std::clamp(m_ui->renderModeCombo->currentIndex(), 0,
                                 static_cast<int>(std::size(kRenderModes)) - 1);
    parameters.renderMode = kRenderModes[index].first;
    parameters.edl = kEdlModes[std::clamp(m_ui->edlCombo->currentIndex(), 0,
                                          static_cast<int>(std::size(kEdlModes)) - 1)]
                         .first;
    parameters.edlStrength = static_cast<float>(m_ui->edlStrengthSpin->value());
    parameters.edlRadiusPx = static_cast<float>(m_ui->edlRadiusSpin->value());
    return parameters;
}

void BuildPanel::setViewParameters(const ViewParameters& parameters) {
    m_ui->thresholdSpin->setValue(parameters.projectionThresholdPx);
    m_ui->budgetSpin->setValue(static_cast<int>(parameters.pointBudget / 1000));
    m_ui->renderModeCombo->setCurrentIndex(renderModeIndex(parameters.renderMode));
    m_ui->edlCombo->setCurrentIndex(edlModeIndex(parameters.edl));
    m_ui->edlStrengthSpin->setValue(parameters.edlStrength);
    m_ui->edlRadiusSpin->setValue(parameters.edlRadiusPx);
}

void BuildPanel::loadSettings(const QSettings& settings) {
    const PipelineOptions defaults;
    PipelineOptions options;
    // The spin boxes clamp what a hand-edited settings file may hold.
    options.build.maxLevel = settings.value("build/depth", defaults.build.maxLevel).toInt();
    options.build.collapse =
        static_cast<LeafCollapse>(std::clamp(settings.value("build/collapse", 0).toInt(), 0, 2));
    options.build.ratio = settings.value("build/ratio", defaults.build.ratio).toDouble();
    options.build.worklistSize =
        settings.value("build/worklist", qulonglong(defaults.build.worklistSize)).toULongLong();
    options.build.threads = settings.value("build/threads", 0).toInt();
    options.sortChunks = settings.value("build/sortChunks", defaults.sortChunks).toInt();
    parsePointStorage(settings.value("build/pointStore").toString().toStdString(), options.storage);
    options.memoryBudgetBytes = settings.value("build/memoryBudgetMiB", 0).toULongLong() * kMiB;
    options.tempDir = settings.value("build/tempDir").toString().toStdString();
    setPipelineOptions(options);
    const ViewParameters viewDefaults;
    ViewParameters view;
    view.projectionThresholdPx =
        settings.value("view/projectionThresholdPx", viewDefaults.projectionThresholdPx).toDouble();
    view.pointBudget =
        settings.value("view/pointBudget", qulonglong(viewDefaults.pointBudget)).toULongLong();
    view.renderMode = viewDefaults.renderMode;
    const QString modeName = settings.value("view/renderMode").toString();
    for (const auto& [mode, name] : kRenderModes) {
        view.renderMode = modeName == QLatin1String(name) ? mode : view.renderMode;
    }
    if (modeName.isEmpty() && settings.value("view/splats", false).toBool()) {
        view.renderMode = RenderMode::Splats; // written by versions before the render mode
    }
    const QString edlName = settings.value("view/edl").toString();
    for (const auto& [mode, name] : kEdlModes) {
        view.edl = edlName == QLatin1String(name) ? mode : view.edl;
    }
    view.edlStrength = settings.value("view/edlStrength", viewDefaults.edlStrength).toFloat();
    view.edlRadiusPx = settings.value("view/edlRadiusPx", viewDefaults.edlRadiusPx).toFloat();
    setViewParameters(view);
}

void BuildPanel::saveSettings(QSettings& settings) const {
    const PipelineOptions options = pipelineOptions();
    settings.setValue("build/depth", options.build.maxLevel);
    settings.setValue("build/collapse", static_cast<int>(options.build.collapse));
    settings.setValue("build/ratio", options.build.ratio);
    settings.setValue("build/worklist", qulonglong(options.build.worklistSize));
    settings.setValue("build/threads", options.build.threads);
    settings.setValue("build/sortChunks", options.sortChunks);
    settings.setValue("build/pointStore", QLatin1String(toString(options.storage)));
    settings.setValue("build/memoryBudgetMiB", qulonglong(options.memoryBudgetBytes / kMiB));
    settings.setValue("build/tempDir", QString::fromStdString(options.tempDir));
    const ViewParameters view = viewParameters();
    settings.setValue("view/projectionThresholdPx", view.projectionThresholdPx);
    settings.setValue("view/pointBudget", qulonglong(view.pointBudget));
    settings.setValue("view/renderMode",
                      QLatin1String(kRenderModes[renderModeIndex(view.renderMode)].second));
    settings.remove("view/splats");
    settings.setValue("view/edl", QLatin1String(kEdlModes[edlModeIndex(view.edl)].second));
    settings.setValue("view/edlStrength", view.edlStrength);
    settings.setValue("view/edlRadiusPx", view.edlRadiusPx);
}

void BuildPanel::setBusy(bool busy) {
    m_ui->cancelButton->setEnabled(busy);
}

void BuildPanel::requestRebuild() {
    emit rebuildRequested(pipelineOptions().build);
}

} // namespace omicron
