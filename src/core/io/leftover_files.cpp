#include "io/leftover_files.hpp"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <fstream>
#include <signal.h>
#include <vector>

namespace omicron {

std::string processToken() {
    std::ifstream bootFile("/proc/sys/kernel/random/boot_id");
    std::string boot;
    std::getline(bootFile, boot);
    std::error_code error;
    const std::string pidNamespace =
        std::filesystem::read_symlink("/proc/self/ns/pid", error).string();
    std::string namespaceNumber; // "pid:[4026531836]" -> "4026531836"
    for (const char c : pidNamespace) {
        if (c >= '0' && c <= '9') {
            namespaceNumber += c;
        }
    }
    if (boot.size() < 8 || error || namespaceNumber.empty()) {
        return "";
    }
    return boot.substr(0, 8) + "." + namespaceNumber;
}

std::string temporaryPrefix(const std::string& name, const std::string& token) {
    std::string prefix("."); // appended, not "." + ...: GCC 12 warns wrongly on that (restrict)
    prefix.append(name).append(".tmp-");
    if (!token.empty()) {
        prefix.append(token).append("-");
    }
    return prefix;
}

void removeLeftoversOfGoneProcesses(const std::filesystem::path& folder, const std::string& prefix,
                                    const std::function<bool(std::string_view tail)>& tailMatches) {
    namespace fs = std::filesystem;
    std::vector<fs::path> gone;
    std::error_code error;
    for (fs::directory_iterator entry(folder, error), end; !error && entry != end;
         entry.increment(error)) {
        const std::string name = entry->path().filename().string();
        if (!name.starts_with(prefix)) {
            continue;
        }
        const char* digits = name.c_str() + prefix.size();
        char* tail = nullptr;
        const long pid = std::strtol(digits, &tail, 10);
        if (tail == digits || pid <= 0 || pid > INT_MAX || !tailMatches(tail)) {
            continue;
        }
        if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
            gone.push_back(entry->path());
        }
    }
    for (const fs::path& path : gone) {
        fs::remove_all(path, error); // another process may be removing it too
    }
}

} // namespace omicron
