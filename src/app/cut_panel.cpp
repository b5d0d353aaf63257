#include "cut_panel.hpp"

#include "level_model.hpp"
#include "ui_cutpanel.h"

#include <QHeaderView>
#include <QLocale>

namespace omicron {

namespace {

int permille(std::uint64_t part, std::uint64_t whole) {
    return whole == 0 ? 0 : static_cast<int>(std::min<std::uint64_t>(1000, part * 1000 / whole));
}

QString barText(std::uint64_t part, std::uint64_t whole) {
    const QLocale locale;
    return QStringLiteral("%1 / %2").arg(locale.toString(quint64(part)),
                                         locale.toString(quint64(whole)));
}

} // namespace

CutPanel::CutPanel(QWidget* parent)
    : QWidget(parent), m_ui(std::make_unique<Ui::CutPanel>()), m_levels(new LevelModel(this)) {
    m_ui->setupUi(this);
    m_ui->levelTable->setModel(m_levels);
    m_ui->levelTable->verticalHeader()->hide();
    m_ui->levelTable->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    clear();
}

CutPanel::~CutPanel() = default;

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
    m_ui->phaseLabel->setText(QString::fromLatin1(toString(progress.phase)));
    const std::uint64_t total = progress.pointsTotal;
    m_ui->readBar->setValue(permille(progress.pointsRead, total));
    m_ui->readBar->setFormat(barText(progress.pointsRead, total));
    m_ui->sortedBar->setValue(permille(progress.pointsSorted, total));
    m_ui->sortedBar->setFormat(barText(progress.pointsSorted, total));
    m_ui->insertedBar->setValue(permille(progress.pointsInserted, total));
    m_ui->insertedBar->setFormat(barText(progress.pointsInserted, total));
    const int swept = sweptPermille(progress.cutDelimiter, progress.maxLevel);
    m_ui->cutBar->setValue(swept);
    m_ui->cutBar->setFormat(progress.cutDelimiter == 0 ? tr("no fix pass yet")
                                                       : QStringLiteral("%1 %  (m_C = 0x%2)")
                                                             .arg(swept / 10.0, 0, 'f', 1)
                                                             .arg(progress.cutDelimiter, 0, 16));
}

void CutPanel::setStatistics(const BuildStatistics& statistics) {
    m_levels->setStatistics(statistics);
    const QLocale locale;
    m_ui->summaryLabel->setText(
        tr("%1 nodes · %2 fix passes (%3 restarted) · %4 duplicate parents merged · "
           "%5 placeholders (%6 substituted) · %7 MiB")
            .arg(locale.toString(quint64(statistics.totalNodes())))
            .arg(statistics.fixPasses)
            .arg(statistics.passesRestarted)
            .arg(statistics.duplicateParentsMerged)
            .arg(statistics.placeholdersCreated)
            .arg(statistics.placeholdersSubstituted)
            .arg(statistics.bytesResident() / 1048576.0, 0, 'f', 1));
}

void CutPanel::clear() {
    setProgress({});
    m_levels->clear();
    m_ui->summaryLabel->clear();
}

} // namespace omicron
