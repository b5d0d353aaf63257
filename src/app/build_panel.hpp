// BuildPanel: the build parameters dock (form ui/buildpanel.ui): depth, leaf collapse, ratio,
// worklist size, threads, sort chunks; and the render parameters that apply at once
// (projection threshold, point budget, render mode). Apply/Rebuild asks for a new
// hierarchy from the kept sorted points.
#pragma once

#include "pipeline/build_pipeline.hpp"
#include "view_parameters.hpp"

#include <QWidget>
#include <memory>

class QSettings;

namespace Ui {
class BuildPanel;
}

namespace omicron {

class BuildPanel : public QWidget {
    Q_OBJECT
public:
    explicit BuildPanel(QWidget* parent = nullptr);
    ~BuildPanel() override;

    PipelineOptions pipelineOptions() const;
    void setPipelineOptions(const PipelineOptions& options);
    ViewParameters viewParameters() const;
    void setViewParameters(const ViewParameters& parameters);

    void loadSettings(const QSettings& settings);
    void saveSettings(QSettings& settings) const;

public slots:
    // While a job runs, Cancel is enabled.
    void setBusy(bool busy);
    void requestRebuild();

signals:
    void rebuildRequested(const omicron::BuildOptions& options);
    void cancelRequested();
    void viewParametersChanged(const omicron::ViewParameters& parameters);

private:
    std::unique_ptr<Ui::BuildPanel> m_ui;
};

} // namespace omicron
