#include "points/huge_page_policy.hpp"

#include <cstdlib>
#include <fstream>

namespace omicron {

namespace {

constexpr const char* kPageReportingParameters = "/sys/module/page_reporting/parameters";

} // namespace

bool hugePagesPayOff(const std::optional<std::string>& override,
                     const std::string& pageReportingParameters) {
    if (override == "0") {
        return false;
    }
    if (override == "1") {
        return true;
    }
    std::ifstream reported(pageReportingParameters + "/reported_kib");
    unsigned long long kib = 0;
    return !(reported >> kib) || kib == 0;
}

bool hugePagesPayOff() {
    static const bool payOff = [] {
        const char* value = std::getenv("OMICRON_HUGE_PAGES");
        return hugePagesPayOff(value ? std::optional<std::string>(value) : std::nullopt,
                               kPageReportingParameters);
    }();
    return payOff;
}

} // namespace omicron
