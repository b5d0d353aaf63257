// LevelModel: the per-level table of the cut progress panel. One row per hierarchy level,
// filled from BuildStatistics snapshots: roots of L_C, nodes created (and leaves), points held,
// placeholders pending in L_l and substituted into leaves of the level.
#pragma once

#include "build_statistics.hpp"

#include <QAbstractTableModel>
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
    void clear();

    // The raw number of `column` at `level` (Level: the level itself).
    quint64 value(int level, Column column) const;

private:
    std::vector<LevelStatistics> m_levels;
};

} // namespace omicron
