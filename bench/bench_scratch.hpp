// Scratch files and folders of the benchmarks, in the temp folder and named PREFIX-PID (plus an
// extension for a file): removed when the run ends, also on an error (ScratchPath's destructor).
// A run killed by a signal (Ctrl+C, a timeout) cannot remove its own, and those hold gigabytes
// for a large cloud (read_bench's input in four formats), so each run first removes the ones
// of its benchmark whose process is gone.
#pragma once

#include "io/leftover_files.hpp"

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <unistd.h>

namespace omicron::bench {

// This run's scratch path, temp folder / PREFIX PID EXTENSION, after removing the stale ones;
// removed (with what it holds) on destruction unless keep() was called.
class ScratchPath {
public:
    explicit ScratchPath(const std::string& prefix, const std::string& extension = "")
        : m_prefix(prefix), m_extension(extension),
          m_path(std::filesystem::temp_directory_path() /
                 (prefix + std::to_string(::getpid()) + extension)) {
        // A run killed before it could remove its own (Ctrl+C, a timeout) left it behind.
        removeLeftoversOfGoneProcesses(std::filesystem::temp_directory_path(), prefix,
                                       [&](std::string_view tail) { return tail == extension; });
    }
    ScratchPath(const ScratchPath&) = delete;
    ScratchPath& operator=(const ScratchPath&) = delete;
    ~ScratchPath() {
        std::error_code error;
        if (!m_keep) {
            std::filesystem::remove_all(m_path, error);
            return;
        }
        // Renamed to a name the removal of leftovers leaves alone.
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
