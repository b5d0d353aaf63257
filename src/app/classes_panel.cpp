#include "classes_panel.hpp"

#include "build/hierarchy.hpp"
#include "class_model.hpp"

#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLocale>
#include <QPushButton>
#include <QTableView>
#include <QVBoxLayout>

namespace omicron {

namespace {

// While counting, the legend is refreshed this often (the counter publishes per chunk).
constexpr int kPollMs = 200;

} // namespace

ClassesPanel::ClassesPanel(QWidget* parent) : QWidget(parent), m_model(new ClassModel(this)) {
    m_table = new QTableView(this);
    m_table->setObjectName(QStringLiteral("classesTable"));
    m_table->setModel(m_model);
    m_table->verticalHeader()->hide();
    m_table->setSelectionMode(QAbstractItemView::NoSelection);
    m_table->setEditTriggers(QAbstractItemView::NoEditTriggers);
    // The name takes what the number and count columns leave (fitColumns sizes those).
    m_table->horizontalHeader()->setSectionResizeMode(ClassModel::NameColumn, QHeaderView::Stretch);
    m_summary = new QLabel(this);
    m_summary->setObjectName(QStringLiteral("classesSummary"));
    m_summary->setWordWrap(true);
    m_showAll = new QPushButton(tr("Show all"), this);
    m_showAll->setObjectName(QStringLiteral("showAllClasses"));
    m_hideAll = new QPushButton(tr("Hide all"), this);
    m_hideAll->setObjectName(QStringLiteral("hideAllClasses"));

    auto* buttons = new QHBoxLayout;
    buttons->addWidget(m_showAll);
    buttons->addWidget(m_hideAll);
    buttons->addStretch();
    auto* layout = new QVBoxLayout(this);
    layout->addWidget(m_table);
    layout->addLayout(buttons);
    layout->addWidget(m_summary);

    connect(m_model, &ClassModel::classVisibilityChanged, this,
            &ClassesPanel::classVisibilityChanged);
    connect(m_showAll, &QPushButton::clicked, this, [this] { emit allClassesHidden(false); });
    connect(m_hideAll, &QPushButton::clicked, this, [this] { emit allClassesHidden(true); });
    m_pollTimer.setInterval(kPollMs);
    connect(&m_pollTimer, &QTimer::timeout, this, &ClassesPanel::poll);
    poll();
}

ClassesPanel::~ClassesPanel() = default;

void ClassesPanel::setHierarchy(std::shared_ptr<const Hierarchy> hierarchy) {
    m_counter.setHierarchy(std::move(hierarchy));
    poll();
    m_pollTimer.start();
}

void ClassesPanel::setHiddenClasses(const std::bitset<kLasClassCount>& hidden) {
    m_model->setHiddenClasses(hidden);
}

void ClassesPanel::fitColumns() {
    // Sized here rather than by QHeaderView::ResizeToContents, which follows inserted rows but
    // not grown counts, nor contents that changed while the dock's tab was hidden.
    m_table->resizeColumnToContents(ClassModel::ClassColumn);
    m_table->resizeColumnToContents(ClassModel::PointsColumn);
}

void ClassesPanel::showEvent(QShowEvent* event) {
    QWidget::showEvent(event);
    fitColumns();
}

void ClassesPanel::poll() {
    const ClassCounter::Snapshot previous = m_counts;
    m_counts = m_counter.snapshot();
    m_model->setCounts(m_counts.counts);
    if (m_counts.counts != previous.counts) {
        fitColumns();
    }
    const QLocale locale;
    QString text;
    if (m_counts.total == 0) {
        text = tr("No cloud");
    } else if (m_counts.notCounted) {
        text = tr("A hierarchy paged in on demand: its points are read only as the view needs "
                  "them, so its classes are not counted");
    } else if (!m_counts.hasClasses) {
        text = tr("The cloud has no classes (no LAS classification): every point is class 0");
    } else if (!m_counts.complete) {
        text = tr("Counting: %1 of %2 points")
                   .arg(locale.toString(quint64(m_counts.counted)),
                        locale.toString(quint64(m_counts.total)));
    } else {
        text = tr("%1 points in %n class(es)", nullptr, int(m_model->classes().size()))
                   .arg(locale.toString(quint64(m_counts.counted)));
    }
    m_summary->setText(text);
    if (m_counts.complete || m_counts.notCounted || m_counts.total == 0) {
        m_pollTimer.stop();
    }
    emit countsChanged();
}

} // namespace omicron
