#include "measurements_panel.hpp"

#include <QApplication>
#include <QClipboard>
#include <QFileDialog>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QPushButton>
#include <QSaveFile>
#include <QTableWidget>
#include <QVBoxLayout>
#include <algorithm>

namespace omicron {

namespace {

QString coordinates(const glm::dvec3& p, QChar separator) {
    return QString::number(p.x, 'f', 4) + separator + QString::number(p.y, 'f', 4) + separator +
           QString::number(p.z, 'f', 4);
}

} // namespace

MeasurementsPanel::MeasurementsPanel(QWidget* parent) : QWidget(parent) {
    auto* column = new QVBoxLayout(this);
    column->setContentsMargins(2, 2, 2, 2);
    m_table = new QTableWidget(0, 4, this);
    m_table->setObjectName(QStringLiteral("measurementsTable"));
    m_table->setHorizontalHeaderLabels(
        {tr("#"), tr("Kind"), tr("Value"), tr("Points (file coordinates)")});
    m_table->verticalHeader()->hide();
    m_table->setSelectionBehavior(QAbstractItemView::SelectRows);
    m_table->setEditTriggers(QAbstractItemView::NoEditTriggers);
    m_table->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    m_table->horizontalHeader()->setStretchLastSection(true);
    m_table->setToolTip(tr("Measurements taken in the view (Measure menu, M): values in the "
                           "file's units, between points picked on the cloud"));
    column->addWidget(m_table, 1);
    auto* buttons = new QHBoxLayout();
    const auto button = [&](const QString& text, const QString& name, const QString& tip) {
        auto* b = new QPushButton(text, this);
        b->setObjectName(name);
        b->setToolTip(tip);
        buttons->addWidget(b);
        return b;
    };
    QPushButton* copy = button(tr("Copy"), QStringLiteral("copyMeasurements"),
                               tr("Copy the selected measurements (or all) as tab-separated "
                                  "text"));
    QPushButton* remove =
        button(tr("Delete"), QStringLiteral("deleteMeasurements"), tr("Delete the selected"));
    QPushButton* clear =
        button(tr("Clear"), QStringLiteral("clearMeasurements"), tr("Delete all"));
    QPushButton* exportButton = button(tr("Export CSV…"), QStringLiteral("exportMeasurements"),
                                       tr("Save all measurements as CSV"));
    buttons->addStretch(1);
    column->addLayout(buttons);
    connect(copy, &QPushButton::clicked, this,
            [this] { QApplication::clipboard()->setText(selectionText()); });
    connect(remove, &QPushButton::clicked, this, [this] {
        std::vector<std::size_t> indices = selectedIndices();
        std::sort(indices.rbegin(), indices.rend());
        if (!indices.empty()) {
            emit removeRequested(indices);
        }
    });
    connect(clear, &QPushButton::clicked, this, &MeasurementsPanel::clearRequested);
    connect(exportButton, &QPushButton::clicked, this, [this] {
        const QString path = QFileDialog::getSaveFileName(this, tr("Export Measurements"),
                                                          QStringLiteral("measurements.csv"),
                                                          tr("CSV files (*.csv)"));
        QString error;
        if (!path.isEmpty() && !exportCsv(path, &error)) {
            emit exportFailed(path, error);
        }
    });
}

void MeasurementsPanel::setMeasurements(const std::vector<Measurement>& measurements) {
    m_measurements = measurements;
    m_table->setRowCount(static_cast<int>(measurements.size()));
    for (std::size_t i = 0; i < measurements.size(); ++i) {
        const Measurement& m = measurements[i];
        QStringList points;
        for (const glm::dvec3& p : m.points) {
            points.append(QStringLiteral("(%1)").arg(coordinates(p, QLatin1Char(' '))));
        }
        const QString cells[4] = {QString::number(i + 1), Measurement::kindName(m.kind),
                                  m.valueText(), points.join(QStringLiteral(" "))};
        for (int c = 0; c < 4; ++c) {
            auto* item = new QTableWidgetItem(cells[c]);
            item->setToolTip(cells[c]);
            m_table->setItem(static_cast<int>(i), c, item);
        }
    }
}

std::vector<std::size_t> MeasurementsPanel::selectedIndices() const {
    std::vector<std::size_t> indices;
    for (const QModelIndex& row : m_table->selectionModel()->selectedRows()) {
        indices.push_back(static_cast<std::size_t>(row.row()));
    }
    return indices;
}

QString MeasurementsPanel::rowsText(const std::vector<std::size_t>& indices,
                                    QChar separator) const {
    QString text = QStringList({QStringLiteral("measurement"), QStringLiteral("kind"),
                                QStringLiteral("value"), QStringLiteral("point"),
                                QStringLiteral("x"), QStringLiteral("y"), QStringLiteral("z")})
                       .join(separator) +
                   QLatin1Char('\n');
    for (const std::size_t i : indices) {
        const Measurement& m = m_measurements[i];
        for (std::size_t p = 0; p < m.points.size(); ++p) {
            text += QString::number(i + 1) + separator + Measurement::kindName(m.kind) +
                    separator + QString::number(m.value(), 'f', 6) + separator +
                    QString::number(p + 1) + separator + coordinates(m.points[p], separator) +
                    QLatin1Char('\n');
        }
    }
    return text;
}

QString MeasurementsPanel::selectionText() const {
    std::vector<std::size_t> indices = selectedIndices();
    if (indices.empty()) {
        for (std::size_t i = 0; i < m_measurements.size(); ++i) {
            indices.push_back(i);
        }
    }
    std::sort(indices.begin(), indices.end());
    return rowsText(indices, QLatin1Char('\t'));
}

bool MeasurementsPanel::exportCsv(const QString& path, QString* error) const {
    std::vector<std::size_t> all;
    for (std::size_t i = 0; i < m_measurements.size(); ++i) {
        all.push_back(i);
    }
    QSaveFile file(path); // the old file stays until the new one is complete
    if (!file.open(QIODevice::WriteOnly | QIODevice::Text)) {
        if (error != nullptr) {
            *error = tr("%1: cannot open for writing: %2").arg(path, file.errorString());
        }
        return false;
    }
    file.write(rowsText(all, QLatin1Char(',')).toUtf8());
    if (!file.commit()) {
        if (error != nullptr) {
            *error = tr("%1: write failed: %2").arg(path, file.errorString());
        }
        return false;
    }
    return true;
}

} // namespace omicron
