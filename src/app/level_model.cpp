#include "level_model.hpp"

#include <QLocale>

namespace omicron {

namespace {

bool sameRow(const LevelStatistics& a, const LevelStatistics& b) {
    return a.nodes == b.nodes && a.leaves == b.leaves && a.points == b.points &&
           a.cutRoots == b.cutRoots && a.placeholdersPending == b.placeholdersPending &&
           a.placeholdersSubstituted == b.placeholdersSubstituted;
}

} // namespace

LevelModel::LevelModel(QObject* parent) : QAbstractTableModel(parent) {}

int LevelModel::rowCount(const QModelIndex& parent) const {
    return parent.isValid() ? 0 : static_cast<int>(m_levels.size());
}

int LevelModel::columnCount(const QModelIndex& parent) const {
    return parent.isValid() ? 0 : ColumnCount;
}

quint64 LevelModel::value(int level, Column column) const {
    const LevelStatistics& row = m_levels.at(static_cast<std::size_t>(level));
    switch (column) {
    case Level:
        return static_cast<quint64>(level);
    case CutRoots:
        return row.cutRoots;
    case Nodes:
        return row.nodes;
    case Leaves:
        return row.leaves;
    case Points:
        return row.points;
    case PlaceholdersPending:
        return row.placeholdersPending;
    case PlaceholdersSubstituted:
        return row.placeholdersSubstituted;
    case FrontNodes:
        return static_cast<std::size_t>(level) < m_frontNodes.size()
                   ? m_frontNodes[static_cast<std::size_t>(level)]
                   : 0;
    case ColumnCount:
        break;
    }
    return 0;
}

QVariant LevelModel::data(const QModelIndex& index, int role) const {
    if (!checkIndex(index, CheckIndexOption::IndexIsValid | CheckIndexOption::ParentIsInvalid)) {
        return {};
    }
    const auto column = static_cast<Column>(index.column());
    const quint64 number = value(index.row(), column);
    switch (role) {
    case Qt::DisplayRole:
        return column == Level ? QString::number(number) : QLocale().toString(number);
    case Qt::EditRole: // raw numbers, for sorting proxies and tests
        return QVariant::fromValue(number);
    case Qt::TextAlignmentRole:
        return QVariant::fromValue(Qt::AlignRight | Qt::AlignVCenter);
    default:
        return {};
    }
}

QVariant LevelModel::headerData(int section, Qt::Orientation orientation, int role) const {
    if (orientation != Qt::Horizontal || section < 0 || section >= ColumnCount) {
        return {};
    }
    static const char* const titles[ColumnCount] = {
        // Short, so the table fits a side panel; the tooltips say the whole.
        QT_TR_NOOP("Level"),  QT_TR_NOOP("Roots"),   QT_TR_NOOP("Nodes"),  QT_TR_NOOP("Leaves"),
        QT_TR_NOOP("Points"), QT_TR_NOOP("Pending"), QT_TR_NOOP("Subst."), QT_TR_NOOP("Front")};
    static const char* const tips[ColumnCount] = {
        QT_TR_NOOP("Octree level (0 = root)"),
        QT_TR_NOOP("Roots in L_C: subtree roots in this level's list of the oblique cut (placeholders "
                   "included): the boundary the next fix pass continues from"),
        QT_TR_NOOP("Nodes created at this level so far"),
        QT_TR_NOOP("Of those, leaves (at the deepest level, or a placeholder's leaf)"),
        QT_TR_NOOP("Points the level's nodes hold (parents hold a sample of their children)"),
        QT_TR_NOOP("Placeholders of collapsed leaves still rising through this level's list"),
        QT_TR_NOOP("Substituted: placeholders that became leaves at this level"),
        QT_TR_NOOP("Front nodes: the view's render front at this level in the last frame "
                   "(placeholders of leaves not yet substituted included)")};
    if (role == Qt::DisplayRole) {
        return tr(titles[section]);
    }
    if (role == Qt::ToolTipRole) {
        return tr(tips[section]);
    }
    return {};
}

void LevelModel::setStatistics(const BuildStatistics& statistics) {
    if (statistics.levels.size() != m_levels.size()) {
        beginResetModel();
        m_levels = statistics.levels;
        endResetModel();
        return;
    }
    for (std::size_t level = 0; level < m_levels.size(); ++level) {
        if (!sameRow(m_levels[level], statistics.levels[level])) {
            m_levels[level] = statistics.levels[level];
            const int row = static_cast<int>(level);
            emit dataChanged(index(row, 0), index(row, ColumnCount - 1),
                             {Qt::DisplayRole, Qt::EditRole});
        }
    }
}

void LevelModel::setFrontNodes(std::span<const std::size_t> perLevel) {
    if (perLevel.size() > m_frontNodes.size()) {
        m_frontNodes.resize(perLevel.size(), 0);
    }
    for (std::size_t level = 0; level < m_frontNodes.size(); ++level) {
        const quint64 count = level < perLevel.size() ? perLevel[level] : 0;
        if (m_frontNodes[level] == count) {
            continue;
        }
        m_frontNodes[level] = count;
        if (level < m_levels.size()) {
            const QModelIndex cell = index(static_cast<int>(level), FrontNodes);
            emit dataChanged(cell, cell, {Qt::DisplayRole, Qt::EditRole});
        }
    }
}

void LevelModel::clear() {
    m_frontNodes.clear();
    if (m_levels.empty()) {
        return;
    }
    beginResetModel();
    m_levels.clear();
    endResetModel();
}

} // namespace omicron
