// Helpers of the application's QtTest executables.
#pragma once

#include <QString>

namespace omicron::apptest {

// ../shared/data/NAME, or an empty string when absent (the test then QSKIPs).
QString sharedDataFile(const QString& name);

} // namespace omicron::apptest

// QSKIPs the current test when ../shared/data/NAME is absent; else sets VAR to its path.
#define OMICRON_REQUIRE_SHARED_FILE(VAR, NAME)                                                     \
    const QString VAR = ::omicron::apptest::sharedDataFile(NAME);                                  \
    if (VAR.isEmpty()) {                                                                           \
        QSKIP(qPrintable(                                                                          \
            QStringLiteral("shared data file %1 is absent (../shared/data)").arg(NAME)));          \
    }
