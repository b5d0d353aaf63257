// CutPanel: the cut progress dock (form ui/cutpanel.ui): progress bars for input read (or the
// bounds pre-pass of a PLY/XYZ file while it is opened), sorted, inserted and where the cut's
// delimiter m_C stands in the code space of the deepest level; and, one above the other (a
// splitter), the per-level table (LevelModel, with the view's front nodes per level) and the
// tree of the hierarchy's settled top (HierarchyModel) with the selected node's details.
// Selecting a node emits nodeSelected (the window highlights its cell in the view).
#pragma once

#include "pipeline/build_pipeline.hpp"

#include <QWidget>
#include <memory>
#include <optional>
#include <span>

class QTableView;
class QTreeView;

namespace Ui {
class CutPanel;
}

namespace omicron {

class HierarchyModel;
class LevelModel;

class CutPanel : public QWidget {
    Q_OBJECT
public:
    explicit CutPanel(QWidget* parent = nullptr);
    ~CutPanel() override;

    LevelModel* levelModel() const { return m_levels; }
    HierarchyModel* hierarchyModel() const { return m_hierarchy; }
    QTreeView* hierarchyTree() const;
    QTableView* levelTable() const;
    // The panel width at which the level table shows all its columns with the numbers of a
    // cloud of up to a billion points, for the window's first layout.
    int widthForAllLevelColumns() const;
    // Thousandths of the code space of level `maxLevel` below `delimiter` (0..1000).
    static int sweptPermille(morton::Code delimiter, int maxLevel);
    // Bar values in thousandths, for tests: read, sorted, inserted, m_C.
    int barValue(int bar) const;
    QString barText(int bar) const;

    // The node selected in the tree (its code), if any, and its details as shown.
    std::optional<morton::Code> selectedNode() const { return m_selected; }
    QString nodeDetails() const;
    // Selects the node in the tree, expanding the rows above it; false when it is not shown
    // (not settled yet, or not in the current hierarchy).
    bool selectNode(morton::Code code);
    // The view's front at each level, for the table's "Front nodes" column.
    void setFrontNodes(std::span<const std::size_t> perLevel);

public slots:
    void setProgress(const omicron::PipelineProgress& progress);
    // Also refreshes the hierarchy tree: statistics arrive at most 10 times a second.
    void setStatistics(const omicron::BuildStatistics& statistics);
    // A new hierarchy for the tree (nullptr: none); the selection is cleared.
    void setHierarchy(std::shared_ptr<const omicron::Hierarchy> hierarchy);
    // The tree takes what the hierarchy published; a selected row that moved under its newly
    // settled parent stays selected there.
    void refreshHierarchy();
    void clear();

signals:
    void nodeSelected(int level, quint64 code);
    void nodeSelectionCleared();

private:
    void onCurrentNodeChanged(const QModelIndex& current);
    void showNoSelection();
    // Forgets the selected node (if any) and tells the view.
    void clearSelection();

    std::unique_ptr<Ui::CutPanel> m_ui;
    LevelModel* m_levels = nullptr;
    HierarchyModel* m_hierarchy = nullptr;
    std::optional<morton::Code> m_selected;
    bool m_refreshing = false; // row moves of a refresh are not the user's selection
};

} // namespace omicron
