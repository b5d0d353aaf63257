#include "io/atomic_file_writer.hpp"

#include "io/leftover_files.hpp"
#include "nameless_file.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <linux/magic.h>
#include <optional>
#include <string>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

namespace omicron {

namespace {
constexpr std::size_t kBufferBytes = 4 << 20;

// Free bytes of a tmpfs that holds `fd`, or nullopt for any other file system. A tmpfs has no
// blocks to reserve: fallocate there allocates and zeroes the file's memory pages, serially and
// before a byte is written (a quarter of a second a gigabyte here), work a write into the hole
// does anyway, page by page, on whichever thread writes.
std::optional<std::uint64_t> tmpfsFreeBytes(int fd) {
    struct statfs fs {};
    if (::fstatfs(fd, &fs) != 0 || fs.f_type != TMPFS_MAGIC) {
        return std::nullopt;
    }
    return std::uint64_t{fs.f_bavail} * static_cast<std::uint64_t>(fs.f_bsize);
}
} // namespace

AtomicFileWriter::AtomicFileWriter(std::string targetPath) : m_targetPath(std::move(targetPath)) {
    const std::filesystem::path target(m_targetPath);
    if (std::filesystem::is_directory(target)) {
        throw OutputError(m_targetPath + ": is a directory, expected a file name to write");
    }
    const std::filesystem::path folder =
        target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
    // ".NAME.tmp-TOKEN-PID-" + a counter (named at commit) or mkostemp's six characters (named
    // from the start): a process killed before its rename leaves such a name behind, and the
    // next writer of the same target removes those whose process is gone.
    const std::string token = processToken();
    std::string prefix = temporaryPrefix(target.filename().string(), token);
    if (!token.empty()) {
        removeLeftoversOfGoneProcesses(folder, prefix, [](std::string_view tail) {
            return tail.size() >= 2 && tail.size() <= 21 && tail.front() == '-' &&
                   std::all_of(tail.begin() + 1, tail.end(),
                               [](char c) { return std::isalnum(static_cast<unsigned char>(c)); });
        });
    }
    prefix.append(std::to_string(::getpid())).append("-");
    m_tempPrefix = (folder / prefix).string();
    m_fd = openNamelessFile(folder.string(), 0600);
    if (m_fd >= 0 && !canNameFiles(m_fd)) {
        ::close(m_fd); // it could never be renamed onto the target
        m_fd = -1;
    }
    if (m_fd < 0) {
        std::string pattern = m_tempPrefix + "XXXXXX";
        m_fd = ::mkostemp(pattern.data(), O_CLOEXEC);
        if (m_fd < 0) {
            throw OutputError(m_targetPath + ": cannot create a temporary file in " +
                              folder.string() + ": " + std::strerror(errno));
        }
        m_tempPath = pattern;
    }
    // Made 0600 either way; a replaced file keeps its mode, a new one gets the usual 0644.
    struct stat existing {};
    const mode_t mode = ::stat(m_targetPath.c_str(), &existing) == 0 ? (existing.st_mode & 07777)
                                                                      : mode_t{0644};
    ::fchmod(m_fd, mode);
}

AtomicFileWriter::~AtomicFileWriter() {
    m_flusher.reset(); // its thread uses the descriptor
    if (m_fd >= 0) {
        ::close(m_fd);
    }
    if (!m_committed && !m_tempPath.empty()) {
        ::unlink(m_tempPath.c_str());
    }
}

void AtomicFileWriter::fail(const std::string& what, int error) const {
    throw OutputError(m_targetPath + ": " + what + ": " + std::strerror(error));
}

void AtomicFileWriter::flushBuffer() {
    std::size_t done = 0;
    const std::uint8_t* buffer = m_buffer.take(m_buffered).data();
    while (done < m_buffered) {
        const ssize_t wrote = ::write(m_fd, buffer + done, m_buffered - done);
        if (wrote < 0) {
            if (errno == EINTR) {
                continue;
            }
            fail("write failed", errno);
        }
        done += static_cast<std::size_t>(wrote);
    }
    m_buffered = 0;
    m_onFile += done;
    m_writeBehind.advance(*this, m_onFile);
}

void AtomicFileWriter::write(const void* data, std::size_t count) {
    const auto* bytes = static_cast<const char*>(data);
    m_bytesWritten += count;
    while (count > 0) {
        std::uint8_t* buffer = m_buffer.take(kBufferBytes).data();
        const std::size_t room = kBufferBytes - m_buffered;
        const std::size_t take = count < room ? count : room;
        std::memcpy(buffer + m_buffered, bytes, take);
        m_buffered += take;
        bytes += take;
        count -= take;
        if (m_buffered == kBufferBytes) {
            flushBuffer();
        }
    }
}

void AtomicFileWriter::writeAt(std::uint64_t offset, const void* data, std::size_t count) {
    if (offset > m_bytesWritten || count > m_bytesWritten - offset) {
        throw OutputError(m_targetPath + ": writeAt(" + std::to_string(offset) + ", " +
                          std::to_string(count) + " bytes) beyond the " +
                          std::to_string(m_bytesWritten) + " bytes written");
    }
    flushBuffer();
    const auto* bytes = static_cast<const char*>(data);
    while (count > 0) {
        const ssize_t wrote = ::pwrite(m_fd, bytes, count, static_cast<off_t>(offset));
        if (wrote < 0) {
            if (errno == EINTR) {
                continue;
            }
            fail("write failed", errno);
        }
        bytes += wrote;
        count -= static_cast<std::size_t>(wrote);
        offset += static_cast<std::uint64_t>(wrote);
    }
}

void AtomicFileWriter::extendTo(std::uint64_t size) {
    if (size < m_bytesWritten) {
        throw OutputError(m_targetPath + ": extendTo(" + std::to_string(size) + ") below the " +
                          std::to_string(m_bytesWritten) + " bytes written");
    }
    flushBuffer();
    const auto from = static_cast<off_t>(m_onFile);
    const auto count = static_cast<off_t>(size - m_onFile);
    if (count > 0) {
        // Where the file system cannot reserve, the region is left sparse (ftruncate) instead
        // of being written with zeros first; on a tmpfs on purpose.
        const bool reserved = reserve(static_cast<std::uint64_t>(from),
                                      static_cast<std::uint64_t>(count), "the file");
        if (!reserved && ::ftruncate(m_fd, static_cast<off_t>(size)) != 0) {
            fail("cannot extend the file to " + std::to_string(size) + " bytes", errno);
        }
    }
    if (::lseek(m_fd, static_cast<off_t>(size), SEEK_SET) < 0) {
        fail("seek failed", errno);
    }
    m_onFile = m_bytesWritten = size;
    m_writeBehind = WriteBehind(size); // the regions before it are released by their writers
}

bool AtomicFileWriter::reserve(std::uint64_t offset, std::uint64_t count,
                               const std::string& what) const {
    const std::string noRoom =
        "no room for the " + std::to_string(offset + count) + " bytes of " + what;
    if (const std::optional<std::uint64_t> tmpfsFree = tmpfsFreeBytes(m_fd)) {
        if (*tmpfsFree < count) {
            fail(noRoom, ENOSPC);
        }
        return false;
    }
    // fallocate rather than posix_fallocate: where the file system cannot reserve, nothing is
    // written with zeros instead.
    if (::fallocate(m_fd, 0, static_cast<off_t>(offset), static_cast<off_t>(count)) == 0) {
        return true;
    }
    if (errno == ENOSPC || errno == EDQUOT) {
        fail(noRoom, errno);
    }
    return false;
}

void AtomicFileWriter::truncateTo(std::uint64_t size) {
    if (size > m_bytesWritten) {
        throw OutputError(m_targetPath + ": truncateTo(" + std::to_string(size) + ") beyond the " +
                          std::to_string(m_bytesWritten) + " bytes written");
    }
    flushBuffer();
    // Only when it is longer: ftruncate takes the inode's lock even to the same size, and
    // waits there for a concurrent fdatasync of the file (io/file_flusher.hpp; 0.17 s).
    struct stat status {};
    if (::fstat(m_fd, &status) != 0) {
        fail("cannot read the file's size", errno);
    }
    if (static_cast<std::uint64_t>(status.st_size) > size &&
        ::ftruncate(m_fd, static_cast<off_t>(size)) != 0) {
        fail("cannot cut the file to " + std::to_string(size) + " bytes", errno);
    }
    if (::lseek(m_fd, static_cast<off_t>(size), SEEK_SET) < 0) {
        fail("seek failed", errno);
    }
    m_onFile = m_bytesWritten = size;
}

int AtomicFileWriter::openDirect() const {
    // The temporary may have no name yet (nameless_file.hpp): reopened through the process's
    // descriptor table.
    const std::string self = "/proc/self/fd/" + std::to_string(m_fd);
    return ::open(self.c_str(), O_WRONLY | O_DIRECT | O_CLOEXEC);
}

void AtomicFileWriter::startWriteBack(std::uint64_t offset, std::uint64_t count) {
    sync_file_range(m_fd, static_cast<off_t>(offset), static_cast<off_t>(count),
                    SYNC_FILE_RANGE_WRITE);
    if (!m_flusher) { // a big file: the first window is written back
        m_flusher = std::make_unique<FileFlusher>(m_fd);
    }
    m_flusher->request();
}

std::uint64_t AtomicFileWriter::backgroundFlushes() const {
    return m_flusher ? m_flusher->flushes() : 0;
}

void AtomicFileWriter::dropFromCache(std::uint64_t offset, std::uint64_t count) {
    sync_file_range(m_fd, static_cast<off_t>(offset), static_cast<off_t>(count),
                    SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE |
                        SYNC_FILE_RANGE_WAIT_AFTER);
    posix_fadvise(m_fd, static_cast<off_t>(offset), static_cast<off_t>(count),
                  POSIX_FADV_DONTNEED);
    // Remembered for commit(): a page whose blocks the flushing thread's journal commit holds
    // at this moment is skipped (a whole 16 MiB window, now and then, on ext4).
    if (!m_dropped.empty() && m_dropped.back().second == offset) {
        m_dropped.back().second = offset + count;
    } else {
        m_dropped.emplace_back(offset, offset + count);
    }
}

void AtomicFileWriter::nameTemporary() {
    // Unique among this process's saves by the counter and among processes by the PID; a
    // name left by a process killed in the instant between this and the rename is skipped
    // here, and removed by the next writer of the same target (see the constructor).
    static std::atomic<unsigned> counter{0};
    for (int attempt = 0; attempt < 1000; ++attempt) {
        const std::string name = m_tempPrefix + std::to_string(counter.fetch_add(1));
        if (nameFile(m_fd, name)) {
            m_tempPath = name;
            return;
        }
        if (errno != EEXIST) {
            fail("cannot give the finished temporary file a name in its folder", errno);
        }
    }
    fail("cannot give the finished temporary file a name in its folder", EEXIST);
}

void AtomicFileWriter::commit() {
    flushBuffer();
    if (const int error = m_flusher ? m_flusher->stop() : 0; error != 0) {
        fail("fsync failed", error);
    }
    if (::fsync(m_fd) != 0) {
        fail("fsync failed", errno);
    }
    for (const auto& [begin, end] : m_dropped) { // all clean and committed now: none is skipped
        posix_fadvise(m_fd, static_cast<off_t>(begin), static_cast<off_t>(end - begin),
                      POSIX_FADV_DONTNEED);
    }
    if (m_tempPath.empty()) {
        nameTemporary();
    }
    if (::close(m_fd) != 0) {
        m_fd = -1;
        fail("close failed", errno);
    }
    m_fd = -1;
    if (std::rename(m_tempPath.c_str(), m_targetPath.c_str()) != 0) {
        fail("cannot rename the finished temporary file onto it", errno);
    }
    m_committed = true;
}

} // namespace omicron
