#include "cut_panel.hpp"

#include "hierarchy_model.hpp"
#include "level_model.hpp"
#include "ui_cutpanel.h"

#include <QFontMetrics>
#include <QHeaderView>
#include <QItemSelectionModel>
#include <QLayout>
#include <QLocale>
#include <QScrollBar>
#include <QStyle>
#include <QTableView>
#include <QTreeView>
#include <algorithm>

namespace omicron {

namespace {

int permille(std::uint64_t part, std::uint64_t whole) {
    return whole == 0 ? 0 : static_cast<int>(std::min<std::uint64_t>(1000, part * 1000 / whole));
}

QString countText(std::uint64_t part, std::uint64_t whole) {
    const QLocale locale;
    return QStringLiteral("%1 / %2").arg(locale.toString(quint64(part)),
                                         locale.toString(quint64(whole)));
}

} // namespace

CutPanel::CutPanel(QWidget* parent)
    : QWidget(parent), m_ui(std::make_unique<Ui::CutPanel>()), m_levels(new LevelModel(this)),
      m_hierarchy(new HierarchyModel(this)) {
    m_ui->setupUi(this);
    m_ui->levelTable->setModel(m_levels);
    m_ui->levelTable->verticalHeader()->hide();
    m_ui->levelTable->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    m_ui->hierarchyTree->setModel(m_hierarchy);
    m_ui->hierarchyTree->header()->setStretchLastSection(false);
    m_ui->hierarchyTree->header()->setSectionResizeMode(QHeaderView::ResizeToContents);
    // Room for a depth-9 table; the tree takes the rest.
    m_ui->panelSplitter->setSizes({330, 400});
    m_ui->hierarchySplitter->setStretchFactor(0, 3);
    m_ui->hierarchySplitter->setStretchFactor(1, 1);
    connect(m_ui->hierarchyTree->selectionModel(), &QItemSelectionModel::currentChanged, this,
            [this](const QModelIndex& current) { onCurrentNodeChanged(current); });
    clear();
}

CutPanel::~CutPanel() = default;

QTreeView* CutPanel::hierarchyTree() const {
    return m_ui->hierarchyTree;
}

QTableView* CutPanel::levelTable() const {
    return m_ui->levelTable;
}

int CutPanel::widthForAllLevelColumns() const {
    // The widest number each column shows for a billion-point cloud (or its title, if wider).
    static const char* const widest[LevelModel::ColumnCount] = {
        "20", "99,999", "99,999,999", "99,999,999", "999,999,999", "99,999", "99,999", "999,999"};
    const QTableView* table = m_ui->levelTable;
    const QHeaderView* header = table->horizontalHeader();
    const QFontMetrics cellFont(table->font());
    int width = 0;
    for (int column = 0; column < LevelModel::ColumnCount; ++column) {
        const int cell = cellFont.horizontalAdvance(QString::fromLatin1(widest[column])) +
                         2 * table->style()->pixelMetric(QStyle::PM_FocusFrameHMargin) + 8;
        width += std::max(cell, header->sectionSizeHint(column));
    }
    width += 2 * table->frameWidth() + table->verticalScrollBar()->sizeHint().width();
    const QMargins margins = layout()->contentsMargins();
    return width + margins.left() + margins.right() + 24; // the group box and dock frames
}

QString CutPanel::nodeDetails() const {
    return m_ui->nodeDetails->text();
}

void CutPanel::setFrontNodes(std::span<const std::size_t> perLevel) {
    m_levels->setFrontNodes(perLevel);
}

void CutPanel::setHierarchy(std::shared_ptr<const Hierarchy> hierarchy) {
    if (hierarchy == m_hierarchy->hierarchy()) {
        return;
    }
    m_refreshing = true;
    m_hierarchy->setHierarchy(std::move(hierarchy));
    m_refreshing = false;
    clearSelection();
}

void CutPanel::refreshHierarchy() {
    m_refreshing = true;
    m_hierarchy->refresh();
    m_refreshing = false;
    if (!m_selected) {
        return;
    }
    const auto current = m_hierarchy->node(m_ui->hierarchyTree->selectionModel()->currentIndex());
    if (!current ||
        m_hierarchy->hierarchy()->node(current->level, current->index).code != *m_selected) {
        // The selected row went to the top of its parent, which settled: select it there.
        const morton::Code code = *m_selected;
        if (!selectNode(code)) {
            clearSelection();
        }
    }
}

bool CutPanel::selectNode(morton::Code code) {
    const QModelIndex index = m_hierarchy->indexOfNode(code);
    if (!index.isValid()) {
        return false;
    }
    m_ui->hierarchyTree->scrollTo(index); // expands the rows above it
    m_ui->hierarchyTree->selectionModel()->setCurrentIndex(
        index, QItemSelectionModel::ClearAndSelect | QItemSelectionModel::Rows);
    return true;
}

void CutPanel::onCurrentNodeChanged(const QModelIndex& current) {
    if (m_refreshing) {
        return; // refreshHierarchy() puts the selection back where the user left it
    }
    const auto node = m_hierarchy->node(current);
    if (!node) {
        clearSelection();
        return;
    }
    const Hierarchy& hierarchy = *m_hierarchy->hierarchy();
    const morton::Code code = hierarchy.node(node->level, node->index).code;
    m_ui->nodeDetails->setText(describeNode(hierarchy, node->level, node->index));
    if (m_selected != code) {
        m_selected = code;
        emit nodeSelected(node->level, code);
    }
}

void CutPanel::clearSelection() {
    if (!m_selected) {
        return;
    }
    m_selected.reset();
    showNoSelection();
    emit nodeSelectionCleared();
}

void CutPanel::showNoSelection() {
    m_ui->nodeDetails->setText(
        tr("Select a node to see its details; its cell is drawn in the view."));
}

int CutPanel::sweptPermille(morton::Code delimiter, int maxLevel) {
    if (delimiter == 0 || maxLevel < 1) {
        return 0;
    }
    // Codes of level L run from 1 << 3L (the sentinel bit alone) to span(root).
    const morton::Code first = morton::Code{1} << (3 * maxLevel);
    const morton::Code last = morton::span(1, maxLevel);
    if (delimiter <= first) {
        return 0;
    }
    const long double swept =
        static_cast<long double>(delimiter - first) / static_cast<long double>(last - first);
    return static_cast<int>(std::min<long double>(1000.0L, swept * 1000.0L));
}

QString CutPanel::barText(int bar) const {
    switch (bar) {
    case 0:
        return m_ui->readBar->format();
    case 1:
        return m_ui->sortedBar->format();
    case 2:
        return m_ui->insertedBar->format();
    default:
        return m_ui->cutBar->format();
    }
}

int CutPanel::barValue(int bar) const {
    switch (bar) {
    case 0:
        return m_ui->readBar->value();
    case 1:
        return m_ui->sortedBar->value();
    case 2:
        return m_ui->insertedBar->value();
    default:
        return m_ui->cutBar->value();
    }
}

void CutPanel::setProgress(const PipelineProgress& progress) {
    QString phase = QString::fromLatin1(toString(progress.phase));
    if (progress.scanningBounds()) {
        phase = tr("opening: scanning the file for its bounds");
    } else if (progress.sortRuns > 0 && progress.phase == BuildPhase::Reading) {
        phase = tr("reading: beyond the memory budget, %n sorted run(s) spilled to disk", "",
                   static_cast<int>(progress.sortRuns));
    } else if (progress.sortRuns > 0 && progress.phase == BuildPhase::Sorting) {
        phase = tr("merging %n sorted run(s) from disk", "", static_cast<int>(progress.sortRuns));
    }
    m_ui->phaseLabel->setText(phase);
    const std::uint64_t total = progress.pointsTotal;
    if (progress.scanningBounds()) {
        // PLY and XYZ files are read once for their bounds before any point streams.
        m_ui->readBar->setValue(permille(progress.bytesScanned, progress.bytesToScan));
        m_ui->readBar->setFormat(tr("scanning bounds: %1 / %2 MiB")
                                     .arg(progress.bytesScanned / 1048576.0, 0, 'f', 1)
                                     .arg(progress.bytesToScan / 1048576.0, 0, 'f', 1));
    } else {
        m_ui->readBar->setValue(permille(progress.pointsRead, total));
        m_ui->readBar->setFormat(countText(progress.pointsRead, total));
    }
    m_ui->sortedBar->setValue(permille(progress.pointsSorted, total));
    m_ui->sortedBar->setFormat(countText(progress.pointsSorted, total));
    m_ui->insertedBar->setValue(permille(progress.pointsInserted, total));
    m_ui->insertedBar->setFormat(countText(progress.pointsInserted, total));
    const int swept = sweptPermille(progress.cutDelimiter, progress.maxLevel);
    m_ui->cutBar->setValue(swept);
    m_ui->cutBar->setFormat(progress.cutDelimiter == 0 ? tr("no fix pass yet")
                                                       : QStringLiteral("%1 %  (m_C = 0x%2)")
                                                             .arg(swept / 10.0, 0, 'f', 1)
                                                             .arg(progress.cutDelimiter, 0, 16));
}

void CutPanel::setStatistics(const BuildStatistics& statistics) {
    m_levels->setStatistics(statistics);
    refreshHierarchy();
    const QLocale locale;
    m_ui->summaryLabel->setText(
        tr("%1 nodes · %2 fix passes (%3 restarted) · %4 duplicate parents merged · "
           "%5 placeholders (%6 substituted) · %7 MiB (%8 points)")
            .arg(locale.toString(quint64(statistics.totalNodes())))
            .arg(statistics.fixPasses)
            .arg(statistics.passesRestarted)
            .arg(statistics.duplicateParentsMerged)
            .arg(statistics.placeholdersCreated)
            .arg(statistics.placeholdersSubstituted)
            .arg(statistics.bytesResident() / 1048576.0, 0, 'f', 1)
            .arg(QLatin1String(toString(statistics.pointStorage))));
}

void CutPanel::clear() {
    setProgress({});
    m_levels->clear();
    m_ui->summaryLabel->clear();
}

} // namespace omicron
