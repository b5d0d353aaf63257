#include "io/leftover_files.hpp"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <signal.h>
#include <vector>

namespace omicron {

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
