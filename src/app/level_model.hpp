// LevelModel: the per-level table of the cut progress panel. One row per hierarchy level,
// filled from BuildStatistics snapshots: roots of L_C, nodes created (and leaves), points held,
// placeholders pending in L_l and substituted into leaves of the level; and from the view's
// frames: the render front's nodes at each level.
#pragma once

#include "build/build_statistics.hpp"

#include <QAbstractTableModel>
#include <span>
#include <vector>

namespace omicron {

class LevelModel : public QAbstractTableModel {
    Q_OBJECT
public:
    enum Column {
        Level,
        CutRoots,
        Nodes,
        Leaves,
        Points,
        PlaceholdersPending,
        PlaceholdersSubstituted,
        FrontNodes,
        ColumnCount
    };

    explicit LevelModel(QObject* parent = nullptr);

    int rowCount(const QModelIndex& parent = {}) const override;
    int columnCount(const QModelIndex& parent = {}) const override;
    QVariant data(const QModelIndex& index, int role = Qt::DisplayRole) const override;
    QVariant headerData(int section, Qt::Orientation orientation,
                        int role = Qt::DisplayRole) const override;

    // Replaces the rows: a different level count resets the model, otherwise only the rows
    // whose numbers changed emit dataChanged (so selections and scroll positions survive).
    void setStatistics(const BuildStatistics& statistics);
    // The view's front at each level (FrameStats::frontNodesPerLevel): only the cells whose
    // number changed emit dataChanged. Levels beyond the table's rows are kept for when the
    // statistics of a deeper build arrive.
    void setFrontNodes(std::span<const std::size_t> perLevel);
    void clear();

    // The raw number of `column` at `level` (Level: the level itself).
    quint64 value(int level, Column column) const;

private:
    std::vector<LevelStatistics> m_levels;
    std::vector<quint64> m_frontNodes; // by level, as long as the longest seen
};

} // namespace omicron
