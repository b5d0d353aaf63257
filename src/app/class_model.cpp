#include "class_model.hpp"

#include <QColor>
#include <QLocale>
#include <algorithm>

namespace omicron {

ClassModel::ClassModel(QObject* parent) : QAbstractTableModel(parent) {}

std::uint64_t ClassModel::count(int classification) const {
    return classification >= 0 && classification < kLasClassCount
               ? m_counts[static_cast<std::size_t>(classification)]
               : 0;
}

void ClassModel::setCounts(const Counts& counts) {
    bool shrank = false;
    for (std::size_t c = 0; c < counts.size(); ++c) {
        shrank = shrank || counts[c] < m_counts[c];
    }
    if (shrank) {
        // Another cloud: its rows have nothing to do with these.
        beginResetModel();
        m_counts = counts;
        m_classes.clear();
        for (int c = 0; c < kLasClassCount; ++c) {
            if (counts[static_cast<std::size_t>(c)] > 0) {
                m_classes.push_back(c);
            }
        }
        endResetModel();
        return;
    }
    // Counts only grow while a cloud is counted: rows are inserted, never removed.
    for (int c = 0; c < kLasClassCount; ++c) {
        const auto at = static_cast<std::size_t>(c);
        if (counts[at] > 0 && m_counts[at] == 0) {
            const auto row = static_cast<int>(
                std::lower_bound(m_classes.begin(), m_classes.end(), c) - m_classes.begin());
            beginInsertRows({}, row, row);
            m_counts[at] = counts[at];
            m_classes.insert(m_classes.begin() + row, c);
            endInsertRows();
        }
    }
    if (counts != m_counts) {
        m_counts = counts;
        if (!m_classes.empty()) {
            emit dataChanged(index(0, PointsColumn), index(rowCount() - 1, PointsColumn));
        }
    }
}

void ClassModel::setHiddenClasses(const std::bitset<kLasClassCount>& hidden) {
    if (hidden == m_hidden) {
        return;
    }
    m_hidden = hidden;
    if (!m_classes.empty()) {
        emit dataChanged(index(0, ClassColumn), index(rowCount() - 1, ClassColumn),
                         {Qt::CheckStateRole});
    }
}

int ClassModel::rowCount(const QModelIndex& parent) const {
    return parent.isValid() ? 0 : static_cast<int>(m_classes.size());
}

int ClassModel::columnCount(const QModelIndex& parent) const {
    return parent.isValid() ? 0 : ColumnCount;
}

QVariant ClassModel::data(const QModelIndex& index, int role) const {
    if (!checkIndex(index, CheckIndexOption::IndexIsValid | CheckIndexOption::ParentIsInvalid)) {
        return {};
    }
    const int classification = m_classes[static_cast<std::size_t>(index.row())];
    switch (index.column()) {
    case ClassColumn:
        if (role == Qt::DisplayRole) {
            return classification;
        }
        if (role == Qt::DecorationRole) {
            const glm::u8vec3 color = lasClassColor(classification);
            return QColor(color.r, color.g, color.b);
        }
        if (role == Qt::CheckStateRole) {
            return m_hidden.test(static_cast<std::size_t>(classification)) ? Qt::Unchecked
                                                                           : Qt::Checked;
        }
        if (role == Qt::ToolTipRole) {
            return tr("Untick to hide the points of this class in the view");
        }
        break;
    case NameColumn:
        if (role == Qt::DisplayRole) {
            return QString::fromStdString(lasClassName(classification));
        }
        break;
    case PointsColumn:
        if (role == Qt::DisplayRole) {
            return QLocale().toString(quint64(m_counts[static_cast<std::size_t>(classification)]));
        }
        if (role == Qt::TextAlignmentRole) {
            return int(Qt::AlignRight | Qt::AlignVCenter);
        }
        break;
    default:
        break;
    }
    return {};
}

QVariant ClassModel::headerData(int section, Qt::Orientation orientation, int role) const {
    if (orientation != Qt::Horizontal || section < 0 || section >= ColumnCount) {
        return {};
    }
    if (role == Qt::DisplayRole) {
        static const char* const kTitles[ColumnCount] = {"Class", "Name", "Points"};
        return tr(kTitles[section]);
    }
    if (role == Qt::ToolTipRole) {
        static const char* const kTips[ColumnCount] = {
            "ASPRS class number (LAS classification), its colour in the classification mode, "
            "and whether its points are drawn",
            "The class's name in the LAS 1.4 specification", "Points of the cloud in the class"};
        return tr(kTips[section]);
    }
    return {};
}

Qt::ItemFlags ClassModel::flags(const QModelIndex& index) const {
    Qt::ItemFlags flags = QAbstractTableModel::flags(index);
    if (index.isValid() && index.column() == ClassColumn) {
        flags |= Qt::ItemIsUserCheckable;
    }
    return flags;
}

bool ClassModel::setData(const QModelIndex& index, const QVariant& value, int role) {
    if (role != Qt::CheckStateRole || index.column() != ClassColumn ||
        !checkIndex(index, CheckIndexOption::IndexIsValid | CheckIndexOption::ParentIsInvalid)) {
        return false;
    }
    const int classification = m_classes[static_cast<std::size_t>(index.row())];
    const bool visible = value.toInt() == Qt::Checked;
    m_hidden.set(static_cast<std::size_t>(classification), !visible);
    emit dataChanged(index, index, {Qt::CheckStateRole});
    emit classVisibilityChanged(classification, visible);
    return true;
}

} // namespace omicron
