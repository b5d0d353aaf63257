#include "io/file_stream.hpp"

#include "io/input_error.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace omicron {

FileStream::FileStream(std::string path) : m_path(std::move(path)) {
    struct stat status {};
    if (::stat(m_path.c_str(), &status) != 0) {
        throw InputError(InputErrorKind::CannotOpen, m_path, InputLocation::none(),
                         std::string("cannot open: ") + std::strerror(errno));
    }
    if (S_ISDIR(status.st_mode)) {
        throw InputError(InputErrorKind::NotARegularFile, m_path, InputLocation::none(),
                         "is a directory, expected a point-cloud file");
    }
    if (!S_ISREG(status.st_mode)) {
        throw InputError(InputErrorKind::NotARegularFile, m_path, InputLocation::none(),
                         "is not a regular file, expected a point-cloud file");
    }
    m_fd = ::open(m_path.c_str(), O_RDONLY | O_CLOEXEC);
    if (m_fd < 0) {
        throw InputError(InputErrorKind::CannotOpen, m_path, InputLocation::none(),
                         std::string("cannot open: ") + std::strerror(errno));
    }
    m_size = static_cast<std::uint64_t>(status.st_size);
    ::posix_fadvise(m_fd, 0, 0, POSIX_FADV_SEQUENTIAL);
}

FileStream::~FileStream() {
    if (m_fd >= 0) {
        ::close(m_fd);
    }
}

void FileStream::seek(std::uint64_t offset) {
    if (::lseek(m_fd, static_cast<off_t>(offset), SEEK_SET) < 0) {
        throw InputError(InputErrorKind::CannotOpen, m_path, InputLocation::byte(offset),
                         std::string("cannot seek: ") + std::strerror(errno));
    }
    m_position = offset;
}

std::size_t FileStream::read(void* destination, std::size_t count) {
    const std::size_t done = readAt(m_position, destination, count);
    m_position += done;
    return done;
}

std::size_t FileStream::readAt(std::uint64_t offset, void* destination, std::size_t count) const {
    auto* out = static_cast<char*>(destination);
    std::size_t done = 0;
    while (done < count) {
        const ssize_t got =
            ::pread(m_fd, out + done, count - done, static_cast<off_t>(offset + done));
        if (got < 0) {
            if (errno == EINTR) {
                continue;
            }
            throw InputError(InputErrorKind::CannotOpen, m_path, InputLocation::byte(offset + done),
                             std::string("read error: ") + std::strerror(errno));
        }
        if (got == 0) {
            break;
        }
        done += static_cast<std::size_t>(got);
    }
    return done;
}

void FileStream::readExact(void* destination, std::size_t count, const std::string& what) {
    const std::uint64_t start = m_position;
    if (read(destination, count) != count) {
        throw InputError(InputErrorKind::Truncated, m_path, InputLocation::byte(start),
                         "expected " + what + " (" + std::to_string(count) +
                             " bytes), but the file ends at byte " + std::to_string(m_position));
    }
}

} // namespace omicron
