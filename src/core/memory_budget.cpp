#include "memory_budget.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>

namespace omicron {

std::optional<std::uint64_t> parseByteSize(const std::string& text) {
    const char* begin = text.c_str();
    while (*begin == ' ') {
        ++begin;
    }
    if (*begin < '0' || *begin > '9') {
        return std::nullopt; // no sign, no empty number
    }
    char* end = nullptr;
    const double number = std::strtod(begin, &end);
    std::string suffix(end);
    while (!suffix.empty() && suffix.back() == ' ') {
        suffix.pop_back();
    }
    for (char& c : suffix) {
        c = static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
    }
    double unit = 1.0;
    if (suffix.empty() || suffix == "B") {
        unit = 1.0;
    } else if (suffix == "K" || suffix == "KB" || suffix == "KIB") {
        unit = 1024.0;
    } else if (suffix == "M" || suffix == "MB" || suffix == "MIB") {
        unit = double(kMiB);
    } else if (suffix == "G" || suffix == "GB" || suffix == "GIB") {
        unit = double(kGiB);
    } else if (suffix == "T" || suffix == "TB" || suffix == "TIB") {
        unit = double(kGiB) * 1024.0;
    } else {
        return std::nullopt;
    }
    const double bytes = std::floor(number * unit);
    if (!std::isfinite(bytes) || bytes < 0.0 || bytes >= 9.2e18) {
        return std::nullopt;
    }
    return static_cast<std::uint64_t>(bytes);
}

std::string formatByteSize(std::uint64_t bytes) {
    char text[32];
    if (bytes >= kGiB) {
        std::snprintf(text, sizeof text, "%.1f GiB", double(bytes) / double(kGiB));
    } else if (bytes >= kMiB) {
        std::snprintf(text, sizeof text, "%.0f MiB", double(bytes) / double(kMiB));
    } else if (bytes >= 1024) {
        std::snprintf(text, sizeof text, "%.0f KiB", double(bytes) / 1024.0);
    } else {
        std::snprintf(text, sizeof text, "%llu B", static_cast<unsigned long long>(bytes));
    }
    return text;
}

std::uint64_t physicalMemoryBytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long pageSize = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) {
        return 0;
    }
    return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize);
}

ResidentSet processResidentSet() {
    std::FILE* file = std::fopen("/proc/self/statm", "r");
    if (file == nullptr) {
        return {};
    }
    unsigned long long pages = 0, resident = 0, shared = 0;
    const int fields = std::fscanf(file, "%llu %llu %llu", &pages, &resident, &shared);
    std::fclose(file);
    const long pageBytes = ::sysconf(_SC_PAGESIZE);
    if (fields != 3 || pageBytes <= 0) {
        return {};
    }
    const auto page = static_cast<std::uint64_t>(pageBytes);
    return {resident * page, shared * page};
}

std::uint64_t defaultMemoryBudget() {
    const std::uint64_t physical = physicalMemoryBytes();
    return physical == 0 ? 4 * kGiB : physical / 2;
}

} // namespace omicron
