// Scratch files and folders of the benchmarks, in the temp folder and named PREFIX-PID (plus an
// extension for a file): removed when the run ends, also on an error (ScratchPath's destructor).
// A run killed by a signal (Ctrl+C, a timeout) cannot remove its own, and those hold gigabytes
// for a large cloud (read_bench's input in four formats), so each run first removes the ones
// of its benchmark whose process is gone.
#pragma once

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace omicron::bench {

// Removes the entries of the temp folder named `prefix`, a process number and, for a file,
// `extension`, whose process is gone. Best effort: what it cannot list or remove stays.
inline void removeStaleScratch(const std::string& prefix, const std::string& extension = "") {
    namespace fs = std::filesystem;
    try {
        std::error_code error;
        for (const auto& entry : fs::directory_iterator(fs::temp_directory_path(), error)) {
            const std::string name = entry.path().filename().string();
            if (!name.starts_with(prefix) || !name.ends_with(extension) ||
                name.size() <= prefix.size() + extension.size()) {
                continue;
            }
            const std::string digits =
                name.substr(prefix.size(), name.size() - prefix.size() - extension.size());
            if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) {
                continue;
            }
            const auto pid = static_cast<pid_t>(std::stol(digits));
            if (::kill(pid, 0) != 0 && errno == ESRCH) {
                fs::remove_all(entry.path(), error);
            }
        }
    } catch (const fs::filesystem_error&) {
    }
}

// This run's scratch path, temp folder / PREFIX PID EXTENSION, after removing the stale ones;
// removed (with what it holds) on destruction unless keep() was called.
class ScratchPath {
public:
    explicit ScratchPath(const std::string& prefix, const std::string& extension = "")
        : m_prefix(prefix), m_extension(extension),
          m_path(std::filesystem::temp_directory_path() /
                 (prefix + std::to_string(::getpid()) + extension)) {
        removeStaleScratch(prefix, extension);
    }
    ScratchPath(const ScratchPath&) = delete;
    ScratchPath& operator=(const ScratchPath&) = delete;
    ~ScratchPath() {
        std::error_code error;
        if (!m_keep) {
            std::filesystem::remove_all(m_path, error);
            return;
        }
        // Renamed to a name removeStaleScratch leaves alone.
        const auto kept =
            m_path.parent_path() / (m_prefix + "kept-" + std::to_string(::getpid()) + m_extension);
        std::filesystem::rename(m_path, kept, error);
        std::fprintf(stderr, "the scratch files are kept in %s\n", (error ? m_path : kept).c_str());
    }

    const std::filesystem::path& path() const { return m_path; }
    void keep() { m_keep = true; }

private:
    std::string m_prefix;
    std::string m_extension;
    std::filesystem::path m_path;
    bool m_keep = false;
};

} // namespace omicron::bench
