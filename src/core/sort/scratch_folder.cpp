#include "sort/scratch_folder.hpp"

#include "io/atomic_file_writer.hpp"
#include "memory_budget.hpp"
#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <stdexcept>
#include <sys/statvfs.h>
#include <unistd.h>
#include <vector>

namespace omicron {

ScratchFolder::ScratchFolder(const std::string& parent)
    : m_parent(parent.empty() ? defaultParent() : parent) {
    std::string pattern = (std::filesystem::path(m_parent) / "omicron-runs-XXXXXX").string();
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    if (::mkdtemp(name.data()) == nullptr) {
        throw OutputError(m_parent + ": cannot make a scratch folder for the sorted runs there: " +
                          std::strerror(errno) + " (choose another with --temp-dir)");
    }
    m_path = name.data();
}

ScratchFolder::~ScratchFolder() {
    std::error_code ignored; // nothing to report to from a destructor; the folder is ours alone
    std::filesystem::remove_all(m_path, ignored);
}

std::uint64_t ScratchFolder::freeBytes() const {
    struct statvfs status = {};
    if (::statvfs(m_path.c_str(), &status) != 0) {
        return UINT64_MAX;
    }
    return static_cast<std::uint64_t>(status.f_bavail) * status.f_frsize;
}

std::string ScratchFolder::defaultParent() {
    const char* tmp = std::getenv("TMPDIR");
    return tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
}

void ScratchFolder::failWrite(const std::string& file, int error) const {
    throw OutputError(m_parent + ": cannot write the sorted run " +
                      std::filesystem::path(file).filename().string() + ": " +
                      std::strerror(error) + "; the runs of this cloud need " +
                      formatByteSize(m_bytesNeeded) + " (" + std::to_string(m_bytesNeeded) +
                      " bytes), " + std::to_string(m_bytesWritten) +
                      " were written; free space there or choose another folder with "
                      "--temp-dir");
}

ScratchFile::ScratchFile(ScratchFolder& folder, const std::string& name)
    : m_folder(folder), m_path((std::filesystem::path(folder.path()) / name).string()) {
    m_fd = ::open(m_path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (m_fd < 0) {
        m_folder.failWrite(m_path, errno);
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
            m_folder.failWrite(m_path, written < 0 ? errno : ENOSPC);
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
            throw std::runtime_error(m_path + ": cannot read back a sorted run at byte " +
                                     std::to_string(offset) + ": " +
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
