// CutPanel: the cut progress dock (form ui/cutpanel.ui): progress bars for input read, sorted,
// inserted and where the cut's delimiter m_C stands in the code space of the deepest level,
// and the per-level table (LevelModel).
#pragma once

#include "build_pipeline.hpp"

#include <QWidget>
#include <memory>

namespace Ui {
class CutPanel;
}

namespace omicron {

class LevelModel;

class CutPanel : public QWidget {
    Q_OBJECT
public:
    explicit CutPanel(QWidget* parent = nullptr);
    ~CutPanel() override;

    LevelModel* levelModel() const { return m_levels; }
    // Thousandths of the code space of level `maxLevel` below `delimiter` (0..1000).
    static int sweptPermille(morton::Code delimiter, int maxLevel);
    // Bar values in thousandths, for tests: read, sorted, inserted, m_C.
    int barValue(int bar) const;

public slots:
    void setProgress(const omicron::PipelineProgress& progress);
    void setStatistics(const omicron::BuildStatistics& statistics);
    void clear();

private:
    std::unique_ptr<Ui::CutPanel> m_ui;
    LevelModel* m_levels = nullptr;
};

} // namespace omicron
