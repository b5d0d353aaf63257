// ClassesPanel: the Classes dock, a legend of the ASPRS classes present in the cloud (colour
// swatch, number, name, points) whose check boxes show or hide each class in the view, with
// Show all / Hide all. The counts come from a ClassCounter (its own thread), polled by a timer
// while it counts: the GUI thread never walks the cloud.
#pragma once

#include "class_counter.hpp"

#include <QTimer>
#include <QWidget>
#include <bitset>
#include <memory>
#include <vector>

class QLabel;
class QPushButton;
class QTableView;

namespace omicron {

class ClassModel;
class Hierarchy;

class ClassesPanel : public QWidget {
    Q_OBJECT
public:
    explicit ClassesPanel(QWidget* parent = nullptr);
    ~ClassesPanel() override;

    // Counts the classes of `hierarchy`'s cloud (a rebuild over the same points keeps them).
    void setHierarchy(std::shared_ptr<const Hierarchy> hierarchy);
    // The view's hidden classes (RenderSettings::hiddenClasses), for the check boxes.
    void setHiddenClasses(const std::bitset<kLasClassCount>& hidden);

    ClassModel* model() const { return m_model; }
    QTableView* table() const { return m_table; }
    // The counts as last polled.
    const ClassCounter::Snapshot& counts() const { return m_counts; }

signals:
    void classVisibilityChanged(int classification, bool visible);
    // Show all / Hide all: every class present (hidden = true hides them).
    void allClassesHidden(bool hidden);
    // New counts were polled (the classes present may have grown).
    void countsChanged();

protected:
    void showEvent(QShowEvent* event) override;

private:
    void poll();
    void fitColumns();

    ClassCounter m_counter;
    ClassCounter::Snapshot m_counts;
    ClassModel* m_model = nullptr;
    QTableView* m_table = nullptr;
    QLabel* m_summary = nullptr;
    QPushButton* m_showAll = nullptr;
    QPushButton* m_hideAll = nullptr;
    QTimer m_pollTimer;
};

} // namespace omicron
