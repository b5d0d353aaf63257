#include "hierarchy_model.hpp"

#include "front/front_projection.hpp"

#include <QLocale>
#include <QScopedValueRollback>
#include <algorithm>

namespace omicron {

namespace {

// The partition point of `isSettled` over [from, count) of `level` (monotone in the code).
std::size_t settledEnd(const Hierarchy& hierarchy, const PublishedCut& cut, int level,
                       std::size_t from, std::size_t count) {
    if (cut.complete) {
        return count;
    }
    std::size_t low = std::min(from, count), high = count;
    while (low < high) {
        const std::size_t mid = low + (high - low) / 2;
        if (Hierarchy::isSettled(hierarchy.node(level, mid).code, cut, hierarchy.maxLevel())) {
            low = mid + 1;
        } else {
            high = mid;
        }
    }
    return low;
}

} // namespace

QString octantPath(morton::Code code) {
    const int level = morton::level(code);
    if (level == 0) {
        return QStringLiteral("root");
    }
    QString path;
    path.reserve(level);
    for (int l = level - 1; l >= 0; --l) {
        path += QChar(u'0' + static_cast<char16_t>((code >> (3 * l)) & 7));
    }
    return path;
}

QString describeNode(const Hierarchy& hierarchy, int level, std::uint32_t index) {
    const OctreeNode& node = hierarchy.node(level, index);
    const CubeTransform& cube = hierarchy.cloud().cube();
    const CellBox box = cellBox(node.code);
    const glm::dvec3 low = cube.origin + box.min * cube.edge;
    const glm::dvec3 high = low + glm::dvec3(box.edge * cube.edge);
    const QLocale locale;
    const auto point = [](const glm::dvec3& p) {
        return QStringLiteral("(%1, %2, %3)")
            .arg(p.x, 0, 'f', 3)
            .arg(p.y, 0, 'f', 3)
            .arg(p.z, 0, 'f', 3);
    };
    QString kind = node.isLeaf() ? QObject::tr("leaf") : QObject::tr("inner node");
    if (node.has(NodeFlag::Collapsed)) {
        kind += QObject::tr(" (collapsed)");
    }
    const QString row = QStringLiteral("<tr><td><b>%1</b></td><td>%2</td></tr>");
    return QStringLiteral("<table cellspacing=2>") +
           row.arg(QObject::tr("Code"), QStringLiteral("0x%1").arg(node.code, 0, 16)) +
           row.arg(QObject::tr("Level"), QString::number(level)) +
           row.arg(QObject::tr("Octants"), octantPath(node.code)) +
           row.arg(QObject::tr("Kind"), kind) + row.arg(QObject::tr("Cell min"), point(low)) +
           row.arg(QObject::tr("Cell max"), point(high)) +
           row.arg(QObject::tr("Points held"), locale.toString(node.pointCount)) +
           row.arg(QObject::tr("Points covered"), locale.toString(node.coveredCount)) +
           row.arg(QObject::tr("Children"), QString::number(node.childCount)) +
           QStringLiteral("</table>");
}

HierarchyModel::HierarchyModel(QObject* parent) : QAbstractItemModel(parent) {}

HierarchyModel::~HierarchyModel() = default;

void HierarchyModel::setHierarchy(std::shared_ptr<const Hierarchy> hierarchy) {
    {
        // Views walk the model from modelReset(): their fetches wait until the reset is over.
        const QScopedValueRollback<bool> changing(m_changing, true);
        beginResetModel();
        m_hierarchy = std::move(hierarchy);
        m_settled.fill(0);
        m_topFirst.fill(0);
        for (auto& rows : m_top) {
            rows.clear();
        }
        m_waiting.clear();
        endResetModel();
    }
    refresh();
}

HierarchyModel::Item* HierarchyModel::item(const QModelIndex& index) const {
    return index.isValid() ? static_cast<Item*>(index.internalPointer()) : nullptr;
}

int HierarchyModel::topOffset(int level) const {
    std::size_t offset = 0;
    for (int l = 0; l < level; ++l) {
        offset += m_top[l].size();
    }
    return static_cast<int>(offset);
}

int HierarchyModel::topRow(const Item& item) const {
    return topOffset(item.node.level) +
           static_cast<int>(item.node.index - m_topFirst[item.node.level]);
}

std::size_t HierarchyModel::topLevelRows(int level) const {
    return m_top.at(static_cast<std::size_t>(level)).size();
}

const OctreeNode& HierarchyModel::octreeNode(const Item& item) const {
    return m_hierarchy->node(item.node.level, item.node.index);
}

bool HierarchyModel::childrenPublished(const Item& item) const {
    const OctreeNode& node = octreeNode(item);
    return item.node.level < m_hierarchy->maxLevel() &&
           std::size_t{node.firstChild} + node.childCount <=
               m_hierarchy->nodeCount(item.node.level + 1);
}

void HierarchyModel::refresh() {
    // Views and testers walk the model (and call fetchMore()) from the signals a refresh
    // emits, even between a begin and an end: no change may start inside another.
    if (!m_hierarchy || m_changing) {
        return;
    }
    const QScopedValueRollback<bool> changing(m_changing, true);
    const Hierarchy& hierarchy = *m_hierarchy;
    // The cut first, then the counts (shallow to deep): every node the cut says is settled is
    // below its level's count, and every published parent's children are below theirs.
    const PublishedCut cut = hierarchy.publishedCut();
    const int maxLevel = hierarchy.maxLevel();
    std::array<std::size_t, kLevels> counts{};
    for (int level = 0; level <= maxLevel; ++level) {
        counts[level] = hierarchy.nodeCount(level);
        m_settled[level] = settledEnd(hierarchy, cut, level, m_settled[level], counts[level]);
    }
    int offset = 0; // top-level row of the current level's first row
    for (int level = 0; level <= maxLevel; ++level) {
        auto& rows = m_top[level];
        // Nodes whose parent is settled: the children of the settled prefix one level up.
        std::size_t adopted = 0;
        if (level > 0 && m_settled[level - 1] > 0) {
            const OctreeNode& last = hierarchy.node(level - 1, m_settled[level - 1] - 1);
            adopted = std::size_t{last.firstChild} + last.childCount;
        }
        const std::size_t oldFirst = m_topFirst[level];
        const std::size_t oldEnd = oldFirst + rows.size();
        const std::size_t newFirst = std::max(std::min(adopted, m_settled[level]), oldFirst);
        const std::size_t newEnd = std::max(m_settled[level], oldEnd);
        const std::size_t removed = std::min(newFirst, oldEnd) - oldFirst;
        if (removed > 0) {
            beginRemoveRows({}, offset, offset + static_cast<int>(removed) - 1);
            for (std::size_t i = 0; i < removed; ++i) {
                forgetWaiting(*rows.front());
                rows.pop_front();
            }
            m_topFirst[level] = oldFirst + removed;
            endRemoveRows();
        }
        if (rows.empty()) {
            m_topFirst[level] = newFirst;
        }
        const std::size_t appendFrom = m_topFirst[level] + rows.size();
        if (newEnd > appendFrom) {
            const int first = offset + static_cast<int>(rows.size());
            beginInsertRows({}, first, first + static_cast<int>(newEnd - appendFrom) - 1);
            for (std::size_t index = appendFrom; index < newEnd; ++index) {
                auto row = std::make_unique<Item>();
                row->node = {level, static_cast<std::uint32_t>(index)};
                rows.push_back(std::move(row));
            }
            endInsertRows();
        }
        offset += static_cast<int>(rows.size());
    }
    // Expanded rows of a file being loaded top-down whose children have arrived since.
    std::vector<Item*> waiting;
    waiting.swap(m_waiting);
    for (Item* row : waiting) {
        row->waitingForChildren = false;
        const int rowNumber = row->parent ? row->row : topRow(*row);
        fetchChildren(*row, createIndex(rowNumber, 0, row));
    }
}

void HierarchyModel::forgetWaiting(const Item& removedTop) {
    std::erase_if(m_waiting, [&](const Item* row) {
        while (row->parent != nullptr) {
            row = row->parent;
        }
        return row == &removedTop;
    });
}

std::optional<HierarchyModel::NodeRef> HierarchyModel::node(const QModelIndex& index) const {
    const Item* row = item(index);
    if (row == nullptr) {
        return std::nullopt;
    }
    return row->node;
}

QModelIndex HierarchyModel::indexOfNode(morton::Code code) {
    if (!m_hierarchy || !morton::isValid(code) || morton::level(code) > m_hierarchy->maxLevel()) {
        return {};
    }
    const int level = morton::level(code);
    // The shown ancestor at the top: at most one level's top rows hold one.
    for (int top = 0; top <= level; ++top) {
        const morton::Code ancestor = code >> (3 * (level - top));
        const auto& rows = m_top[top];
        if (rows.empty()) {
            continue;
        }
        const auto found = m_hierarchy->findNode(ancestor, m_topFirst[top] + rows.size());
        if (!found || *found < m_topFirst[top]) {
            continue;
        }
        Item* current = rows[*found - m_topFirst[top]].get();
        QModelIndex index = createIndex(topRow(*current), 0, current);
        for (int l = top + 1; l <= level; ++l) {
            if (!current->fetched) {
                fetchChildren(*current, index);
            }
            const morton::Code wanted = code >> (3 * (level - l));
            Item* next = nullptr;
            for (const auto& child : current->children) {
                if (octreeNode(*child).code == wanted) {
                    next = child.get();
                    break;
                }
            }
            if (next == nullptr) {
                return {};
            }
            current = next;
            index = createIndex(current->row, 0, current);
        }
        return index;
    }
    return {};
}

QModelIndex HierarchyModel::index(int row, int column, const QModelIndex& parent) const {
    if (row < 0 || column < 0 || column >= ColumnCount || parent.column() > 0) {
        return {};
    }
    if (const Item* parentItem = item(parent)) {
        if (static_cast<std::size_t>(row) >= parentItem->children.size()) {
            return {};
        }
        return createIndex(row, column, parentItem->children[static_cast<std::size_t>(row)].get());
    }
    int offset = 0;
    for (const auto& rows : m_top) {
        const int size = static_cast<int>(rows.size());
        if (row < offset + size) {
            return createIndex(row, column, rows[static_cast<std::size_t>(row - offset)].get());
        }
        offset += size;
    }
    return {};
}

QModelIndex HierarchyModel::parent(const QModelIndex& child) const {
    const Item* row = item(child);
    if (row == nullptr || row->parent == nullptr) {
        return {};
    }
    const Item* parentItem = row->parent;
    const int parentRow = parentItem->parent != nullptr ? parentItem->row : topRow(*parentItem);
    return createIndex(parentRow, 0, const_cast<Item*>(parentItem));
}

int HierarchyModel::rowCount(const QModelIndex& parent) const {
    if (parent.column() > 0) {
        return 0;
    }
    if (const Item* row = item(parent)) {
        return static_cast<int>(row->children.size());
    }
    return topOffset(kLevels);
}

int HierarchyModel::columnCount(const QModelIndex&) const {
    return ColumnCount;
}

bool HierarchyModel::hasChildren(const QModelIndex& parent) const {
    if (parent.column() > 0) {
        return false;
    }
    if (const Item* row = item(parent)) {
        return row->fetched ? !row->children.empty() : octreeNode(*row).childCount > 0;
    }
    return rowCount() > 0;
}

bool HierarchyModel::canFetchMore(const QModelIndex& parent) const {
    if (!m_hierarchy || parent.column() > 0 || m_changing) {
        return false;
    }
    if (const Item* row = item(parent)) {
        return !row->fetched && !row->waitingForChildren && octreeNode(*row).childCount > 0;
    }
    // The top level changes only in refresh(): it also removes rows (those whose parent
    // settled), and views call fetchMore() in the middle of their own work (a layout, a
    // scrollTo) expecting rows to be added at most.
    return false;
}

void HierarchyModel::fetchMore(const QModelIndex& parent) {
    if (!canFetchMore(parent)) {
        return;
    }
    fetchChildren(*item(parent), parent);
}

void HierarchyModel::fetchChildren(Item& row, const QModelIndex& index) {
    const OctreeNode& node = octreeNode(row);
    if (node.childCount == 0) {
        row.fetched = true;
        return;
    }
    if (!childrenPublished(row)) {
        // A file loading top-down publishes the next level later: refresh() completes it.
        if (!row.waitingForChildren) {
            row.waitingForChildren = true;
            m_waiting.push_back(&row);
        }
        return;
    }
    const QScopedValueRollback<bool> changing(m_changing, true);
    beginInsertRows(index.siblingAtColumn(0), 0, node.childCount - 1);
    row.children.reserve(node.childCount);
    for (int c = 0; c < node.childCount; ++c) {
        auto child = std::make_unique<Item>();
        child->node = {row.node.level + 1, node.firstChild + static_cast<std::uint32_t>(c)};
        child->parent = &row;
        child->row = c;
        row.children.push_back(std::move(child));
    }
    row.fetched = true;
    endInsertRows();
}

QVariant HierarchyModel::data(const QModelIndex& index, int role) const {
    if (!index.isValid() || !checkIndex(index, CheckIndexOption::IndexIsValid)) {
        return {};
    }
    const Item& row = *item(index);
    const OctreeNode& node = octreeNode(row);
    const auto number = [&]() -> quint64 {
        switch (index.column()) {
        case Points:
            return node.pointCount;
        case Covered:
            return node.coveredCount;
        case Children:
            return node.childCount;
        default:
            return static_cast<quint64>(row.node.level);
        }
    };
    switch (role) {
    case Qt::DisplayRole:
        if (index.column() == Node) {
            return QStringLiteral("L%1  %2").arg(row.node.level).arg(octantPath(node.code));
        }
        return QLocale().toString(number());
    case Qt::EditRole:
        return index.column() == Node ? QVariant::fromValue(quint64(node.code))
                                      : QVariant::fromValue(number());
    case Qt::ToolTipRole:
        return describeNode(*m_hierarchy, row.node.level, row.node.index);
    case Qt::TextAlignmentRole:
        return index.column() == Node ? QVariant()
                                      : QVariant::fromValue(Qt::AlignRight | Qt::AlignVCenter);
    case LevelRole:
        return row.node.level;
    case CodeRole:
        return QVariant::fromValue(quint64(node.code));
    case NodeIndexRole:
        return QVariant::fromValue(quint32(row.node.index));
    default:
        return {};
    }
}

QVariant HierarchyModel::headerData(int section, Qt::Orientation orientation, int role) const {
    if (orientation != Qt::Horizontal || section < 0 || section >= ColumnCount) {
        return {};
    }
    static const char* const titles[ColumnCount] = {QT_TR_NOOP("Node"), QT_TR_NOOP("Points"),
                                                    QT_TR_NOOP("Covered"), QT_TR_NOOP("Children")};
    static const char* const tips[ColumnCount] = {
        QT_TR_NOOP("Level and octant path from the root (one digit 0-7 per level)"),
        QT_TR_NOOP("Points the node holds (a parent holds a sample of its children's)"),
        QT_TR_NOOP("Input points in the node's subtree"), QT_TR_NOOP("Child nodes")};
    if (role == Qt::DisplayRole) {
        return tr(titles[section]);
    }
    if (role == Qt::ToolTipRole) {
        return tr(tips[section]);
    }
    return {};
}

} // namespace omicron
