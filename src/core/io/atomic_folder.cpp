#include "io/atomic_folder.hpp"

#include "io/atomic_file_writer.hpp"
#include "io/leftover_files.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sys/stat.h>
#include <unistd.h>

namespace omicron {

namespace {

namespace fs = std::filesystem;

// The target's parent ("." for a bare name): where the temporary folder must live for the
// rename to stay on one file system.
fs::path parentOf(const fs::path& target) {
    const fs::path parent = target.parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

// A name without trailing separators: "out/" and "out" name the same folder, and
// filename() of "out/" is empty.
fs::path normalised(const std::string& path) {
    fs::path target(path);
    while (!target.empty() && !target.has_filename() && target.has_parent_path() &&
           target != target.root_path()) {
        target = target.parent_path();
    }
    return target;
}

void syncFolder(const fs::path& folder) {
    const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        ::fsync(fd); // durability only: a failure here loses nothing already renamed
        ::close(fd);
    }
}

} // namespace

AtomicFolder::AtomicFolder(std::string targetPath, ReplaceCheck mayReplace)
    : m_targetPath(std::move(targetPath)), m_mayReplace(std::move(mayReplace)) {
    const fs::path target = normalised(m_targetPath);
    if (target.empty() || !target.has_filename() || target.filename() == "." ||
        target.filename() == "..") {
        throw OutputError(m_targetPath + ": expected the name of a folder to create");
    }
    checkTarget();
    const fs::path parent = parentOf(target);
    std::error_code error;
    if (!fs::is_directory(parent, error)) {
        throw OutputError(m_targetPath + ": its parent folder " + parent.string() +
                          " does not exist");
    }
    // ".NAME.tmp-TOKEN-PID-XXXXXX": the token and PID say whether its maker still runs.
    const std::string token = processToken();
    const std::string prefix = temporaryPrefix(target.filename().string(), token);
    if (!token.empty()) {
        // Tails "-XXXXXX" only: a folder moved aside during a replace ("....old") is the old
        // export's only copy if its process died between the two renames, and stays.
        removeLeftoversOfGoneProcesses(parent, prefix, [](std::string_view tail) {
            return tail.size() == 7 && tail.front() == '-';
        });
    }
    std::string pattern = (parent / (prefix + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) {
        throw OutputError(m_targetPath + ": cannot create a temporary folder in " +
                          parent.string() + ": " + std::strerror(errno));
    }
    m_tempPath = pattern;
    // mkdtemp creates 0700; the finished folder is meant to be served and shared like any
    // other (AtomicFileWriter gives new files 0644 the same way).
    ::chmod(m_tempPath.c_str(), 0755);
}

AtomicFolder::~AtomicFolder() {
    if (!m_committed && !m_tempPath.empty()) {
        std::error_code ignored; // a destructor must not throw; the folder is ours alone
        fs::remove_all(m_tempPath, ignored);
    }
}

std::string AtomicFolder::file(const std::string& name) const {
    return (fs::path(m_tempPath) / name).string();
}

void AtomicFolder::checkTarget() const {
    const fs::path target = normalised(m_targetPath);
    std::error_code error;
    const fs::file_status status = fs::symlink_status(target, error);
    if (!fs::exists(status)) {
        return;
    }
    if (!fs::is_directory(status)) {
        throw OutputError(m_targetPath + ": exists and is not a folder");
    }
    if (fs::is_empty(target, error)) {
        return;
    }
    if (const std::string refusal =
            m_mayReplace ? m_mayReplace(target.string()) : std::string("the folder is not empty");
        !refusal.empty()) {
        throw OutputError(m_targetPath + ": not replaced: " + refusal);
    }
}

void AtomicFolder::commit() {
    checkTarget(); // the target may have changed while the files were written
    const fs::path target = normalised(m_targetPath);
    const fs::path parent = parentOf(target);
    // A missing or empty target: one rename (rename(2) replaces an empty folder).
    if (::rename(m_tempPath.c_str(), target.c_str()) == 0) {
        m_committed = true;
        syncFolder(parent);
        return;
    }
    if (errno != ENOTEMPTY && errno != EEXIST) {
        throw OutputError(m_targetPath + ": cannot rename " + m_tempPath +
                          " into place: " + std::strerror(errno));
    }
    // An accepted non-empty target: swap the two in one step, so a reader sees the old
    // folder or the new one, then remove the old one (now under the temporary name).
    if (::renameat2(AT_FDCWD, m_tempPath.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0) {
        if (errno != EINVAL && errno != ENOSYS) {
            throw OutputError(m_targetPath + ": cannot exchange it with " + m_tempPath + ": " +
                              std::strerror(errno));
        }
        // A file system without exchange: the old folder steps aside first. Between the two
        // renames the target is missing, never half-written; on failure the old one returns.
        const std::string aside = m_tempPath + ".old";
        if (::rename(target.c_str(), aside.c_str()) != 0) {
            throw OutputError(m_targetPath +
                              ": cannot move the old folder aside: " + std::strerror(errno));
        }
        if (::rename(m_tempPath.c_str(), target.c_str()) != 0) {
            const int renameError = errno;
            ::rename(aside.c_str(), target.c_str());
            throw OutputError(m_targetPath + ": cannot rename " + m_tempPath +
                              " into place: " + std::strerror(renameError));
        }
        m_tempPath = aside;
    }
    syncFolder(parent);
    std::error_code error;
    fs::remove_all(m_tempPath, error);
    m_committed = true;
    if (error) {
        throw OutputError(m_targetPath + ": written, but the replaced folder " + m_tempPath +
                          " could not be removed: " + error.message());
    }
}

} // namespace omicron
