// MeasurementsPanel: the Measurements dock. Lists the view's measurements (kind, value, the
// picked points in the file's coordinates), copies the selected ones (or all) to the
// clipboard as tab-separated text, deletes them, and exports them all as CSV.
#pragma once

#include "measurement.hpp"

#include <QWidget>
#include <vector>

class QTableWidget;

namespace omicron {

class MeasurementsPanel : public QWidget {
    Q_OBJECT
public:
    explicit MeasurementsPanel(QWidget* parent = nullptr);

    // Shows `measurements` (the view's, oldest first).
    void setMeasurements(const std::vector<Measurement>& measurements);
    QTableWidget* table() const { return m_table; }

    // Tab-separated rows (a header, then one row per picked point) of the selected
    // measurements, or of all when none is selected.
    QString selectionText() const;
    // Writes every measurement as CSV (one row per picked point), replacing `path` only once
    // complete; false with `error` naming the file otherwise.
    bool exportCsv(const QString& path, QString* error = nullptr) const;

signals:
    // The user deleted these rows (indices into the list, descending).
    void removeRequested(const std::vector<std::size_t>& indices);
    void clearRequested();
    void exportFailed(const QString& path, const QString& message);

private:
    QString rowsText(const std::vector<std::size_t>& indices, QChar separator) const;
    std::vector<std::size_t> selectedIndices() const;

    QTableWidget* m_table = nullptr;
    std::vector<Measurement> m_measurements;
};

} // namespace omicron
