// ClassModel: the Classes dock's table, one row per ASPRS class present in the cloud (points
// counted > 0), in class order: the class number with its colour swatch and a visibility
// check box, the class name, the point count. It holds a copy of the counts and of the hidden
// set; the window feeds both (ClassCounter, the view's RenderSettings::hiddenClasses).
#pragma once

#include "points/asprs_classes.hpp"

#include <QAbstractTableModel>
#include <array>
#include <bitset>
#include <cstdint>
#include <vector>

namespace omicron {

class ClassModel : public QAbstractTableModel {
    Q_OBJECT
public:
    enum Column { ClassColumn, NameColumn, PointsColumn, ColumnCount };
    using Counts = std::array<std::uint64_t, kLasClassCount>;

    explicit ClassModel(QObject* parent = nullptr);

    // New counts: classes that appear are inserted where they belong, counts updated. Counts
    // of a new cloud (any fewer than before): reset.
    void setCounts(const Counts& counts);
    void setHiddenClasses(const std::bitset<kLasClassCount>& hidden);
    const std::vector<int>& classes() const { return m_classes; } // rows, in class order
    std::uint64_t count(int classification) const;

    int rowCount(const QModelIndex& parent = {}) const override;
    int columnCount(const QModelIndex& parent = {}) const override;
    QVariant data(const QModelIndex& index, int role) const override;
    QVariant headerData(int section, Qt::Orientation orientation, int role) const override;
    Qt::ItemFlags flags(const QModelIndex& index) const override;
    // Qt::CheckStateRole on the class column: shows or hides the class (classVisibilityChanged).
    bool setData(const QModelIndex& index, const QVariant& value, int role) override;

signals:
    void classVisibilityChanged(int classification, bool visible);

private:
    Counts m_counts{};
    std::bitset<kLasClassCount> m_hidden;
    std::vector<int> m_classes;
};

} // namespace omicron
