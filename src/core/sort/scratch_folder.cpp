#include "sort/scratch_folder.hpp"

#include "io/atomic_file_writer.hpp"
#include "memory_budget.hpp"
#include "nameless_file.hpp"
#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <stdexcept>
#include <sys/statvfs.h>
#include <unistd.h>

namespace omicron {

ScratchFolder::ScratchFolder(const std::string& parent)
    : m_parent(parent.empty() ? defaultParent() : parent) {
    // A first file, closed at once: an unusable folder is this error, before any work.
    const int probe = openScratchFile(m_parent, "omicron-run-");
    if (probe < 0) {
        throw OutputError(m_parent + ": cannot make scratch files for the sorted runs there: " +
                          std::strerror(errno) + " (choose another folder with --temp-dir)");
    }
    ::close(probe);
}

std::uint64_t ScratchFolder::freeBytes() const {
    struct statvfs status = {};
    if (::statvfs(m_parent.c_str(), &status) != 0) {
        return UINT64_MAX;
    }
    return static_cast<std::uint64_t>(status.f_bavail) * status.f_frsize;
}

std::string ScratchFolder::defaultParent() {
    const char* tmp = std::getenv("TMPDIR");
    return tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
}

void ScratchFolder::failWrite(const std::string& file, int error) const {
    throw OutputError(m_parent + ": cannot write the sorted run " + file + ": " +
                      std::strerror(error) + "; the runs of this cloud need " +
                      formatByteSize(m_bytesNeeded) + " (" + std::to_string(m_bytesNeeded) +
                      " bytes), " + std::to_string(m_bytesWritten) +
                      " were written; free space there or choose another folder with "
                      "--temp-dir");
}

ScratchFile::ScratchFile(ScratchFolder& folder, const std::string& name)
    : m_folder(folder), m_name(name) {
    m_fd = openScratchFile(folder.parent(), "omicron-" + name + "-");
    if (m_fd < 0) {
        m_folder.failWrite(m_name, errno);
    }
}

ScratchFile::~ScratchFile() {
    if (m_fd >= 0) {
        ::close(m_fd);
    }
}

void ScratchFile::write(const void* data, std::size_t count) {
    const auto* bytes = static_cast<const char*>(data);
    while (count > 0) {
        const ssize_t written = ::write(m_fd, bytes, count);
        if (written < 0 && errno == EINTR) {
            continue;
        }
        if (written <= 0) {
            m_folder.failWrite(m_name, written < 0 ? errno : ENOSPC);
        }
        bytes += written;
        count -= static_cast<std::size_t>(written);
        m_size += static_cast<std::uint64_t>(written);
        m_folder.m_bytesWritten += static_cast<std::uint64_t>(written);
    }
}

void ScratchFile::read(std::uint64_t offset, void* data, std::size_t count) const {
    auto* bytes = static_cast<char*>(data);
    while (count > 0) {
        const ssize_t got = ::pread(m_fd, bytes, count, static_cast<off_t>(offset));
        if (got < 0 && errno == EINTR) {
            continue;
        }
        if (got <= 0) {
            throw std::runtime_error(m_folder.parent() + ": cannot read back the sorted run " +
                                     m_name + " at byte " + std::to_string(offset) + ": " +
                                     (got < 0 ? std::strerror(errno) : "unexpected end"));
        }
        bytes += got;
        count -= static_cast<std::size_t>(got);
        offset += static_cast<std::uint64_t>(got);
    }
}

void ScratchFile::willRead(std::uint64_t offset, std::uint64_t count) const {
    if (offset < m_size) {
        readFileAhead(m_fd, offset, std::min(count, m_size - offset));
    }
}

} // namespace omicron
