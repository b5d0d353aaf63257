// HierarchyModel: the tree of the hierarchy's settled top, for the cut panel's Hierarchy box.
//
// Only settled nodes are shown (Hierarchy::isSettled: published, and neither a root of the
// oblique cut nor a child of one, so their place in the tree never changes). The top-level
// rows are the settled nodes whose parent is not settled yet, grouped by level (shallowest
// first) and in Morton order within a level: while a build runs they are the settled edge of
// the sweep; once it is complete, the root alone. Each level's settled nodes are a prefix of
// its node array (settledness is monotone in the code), so refresh() only ever appends rows
// at the end of a level's group and removes rows from its start, when their parent settles
// (they reappear under it). Children are fetched lazily when a row is expanded
// (canFetchMore/fetchMore); a node never changes once published, so fetched rows stay valid.
// The top level changes only in refresh(), never in fetchMore(): views fetch in the middle of
// a layout or a scrollTo and expect rows to be added there, not removed.
// The hierarchy is read with acquire loads only (its published node counts and the cut), on
// the GUI thread, while the builder threads append.
#pragma once

#include "build/hierarchy.hpp"

#include <QAbstractItemModel>
#include <array>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

namespace omicron {

class HierarchyModel : public QAbstractItemModel {
    Q_OBJECT
public:
    enum Column { Node, Points, Covered, Children, ColumnCount };
    enum Role {
        LevelRole = Qt::UserRole + 1, // int
        CodeRole,                     // quint64: the Morton code with its sentinel bit
        NodeIndexRole,                // quint32: index in the level's node array
    };

    struct NodeRef {
        int level = 0;
        std::uint32_t index = 0;
    };

    explicit HierarchyModel(QObject* parent = nullptr);
    ~HierarchyModel() override;

    // A new hierarchy (nullptr: none): resets the model, then takes what it has published.
    void setHierarchy(std::shared_ptr<const Hierarchy> hierarchy);
    const std::shared_ptr<const Hierarchy>& hierarchy() const { return m_hierarchy; }

    // Takes what the hierarchy published since the last call (the cut panel calls it at
    // 10 Hz): rows for newly settled nodes, rows moved under parents that settled, children
    // of expanded rows that a loading file has published since.
    void refresh();

    // The node behind `index`; nothing for an invalid index.
    std::optional<NodeRef> node(const QModelIndex& index) const;
    // The index (column 0) of the node with `code`, fetching the rows on its path; invalid when
    // the node is not shown (not settled yet, or not in this hierarchy).
    QModelIndex indexOfNode(morton::Code code);
    // Rows at the top level per level, for tests and the panel's summary.
    std::size_t topLevelRows(int level) const;

    QModelIndex index(int row, int column, const QModelIndex& parent = {}) const override;
    QModelIndex parent(const QModelIndex& child) const override;
    int rowCount(const QModelIndex& parent = {}) const override;
    int columnCount(const QModelIndex& parent = {}) const override;
    bool hasChildren(const QModelIndex& parent = {}) const override;
    bool canFetchMore(const QModelIndex& parent) const override;
    void fetchMore(const QModelIndex& parent) override;
    QVariant data(const QModelIndex& index, int role = Qt::DisplayRole) const override;
    QVariant headerData(int section, Qt::Orientation orientation,
                        int role = Qt::DisplayRole) const override;

private:
    struct Item {
        NodeRef node;
        Item* parent = nullptr; // nullptr: a top-level row
        int row = 0;            // among its parent's children (top-level rows: computed)
        bool fetched = false;
        bool waitingForChildren = false; // expanded before a loading file published them
        std::vector<std::unique_ptr<Item>> children;
    };
    static constexpr int kLevels = morton::kMaxLevel + 1;

    Item* item(const QModelIndex& index) const;
    int topRow(const Item& item) const;
    int topOffset(int level) const;
    const OctreeNode& octreeNode(const Item& item) const;
    bool childrenPublished(const Item& item) const;
    void fetchChildren(Item& item, const QModelIndex& index);
    void forgetWaiting(const Item& removedTop);

    std::shared_ptr<const Hierarchy> m_hierarchy;
    // Per level: the settled prefix seen so far, and the top-level rows (node indices
    // [m_topFirst, m_topFirst + m_top.size())).
    std::array<std::size_t, kLevels> m_settled{};
    std::array<std::size_t, kLevels> m_topFirst{};
    std::array<std::deque<std::unique_ptr<Item>>, kLevels> m_top;
    std::vector<Item*> m_waiting; // rows whose children a loading file has not published yet
    bool m_changing = false;      // inside a begin/end pair: no fetch may start another
};

// What the cut panel shows of a node: code, level, octant path, cell in source units, points
// held and covered, children, leaf flags (rich text).
QString describeNode(const Hierarchy& hierarchy, int level, std::uint32_t index);

// The node's octant path from the root, one digit 0..7 per level ("root" for level 0).
QString octantPath(morton::Code code);

} // namespace omicron
