#include "app_test_support.hpp"

#include <QDir>
#include <QFileInfo>

namespace omicron::apptest {

QString sharedDataFile(const QString& name) {
    const QString path = QDir(QStringLiteral(OMICRON_SHARED_DATA_DIR)).filePath(name);
    return QFileInfo::exists(path) ? QFileInfo(path).absoluteFilePath() : QString();
}

} // namespace omicron::apptest
