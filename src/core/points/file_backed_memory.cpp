// The scratch-file mappings of points/huge_page_buffer.hpp (FileBacking).
#include "nameless_file.hpp"
#include "points/huge_page_buffer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <stdexcept>
#include <unistd.h>

namespace omicron {

namespace {

[[noreturn]] void fail(const std::string& folder, std::size_t bytes, const char* what, int error) {
    throw std::runtime_error(
        folder + ": cannot keep " + std::to_string(bytes >> 20) + " MiB (" + std::to_string(bytes) +
        " bytes) of sorted points beyond the memory budget there (" + what + ": " +
        std::strerror(error) + "); free space there or choose another folder with --temp-dir");
}

} // namespace

void* mapScratchFile(const std::string& folder, std::size_t bytes, int& fd) {
    // A file without a name: nothing to remove, whatever way the process ends.
    fd = openScratchFile(folder, "omicron-cloud-");
    if (fd < 0) {
        fail(folder, bytes, "creating the file", errno);
    }
    // Reserved now, so a full disk is this error and not a SIGBUS when a page is written back.
    const int reserved = posix_fallocate(fd, 0, static_cast<off_t>(bytes));
    if (reserved != 0) {
        close(fd);
        fail(folder, bytes, "reserving its space", reserved);
    }
    void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (memory == MAP_FAILED) {
        const int mapError = errno;
        close(fd);
        fail(folder, bytes, "mapping it", mapError);
    }
    // No fault-around: a fault maps its own page only. With it, one pass of parents' samples
    // (a pick every few hundred bytes) maps every cached page of the cloud within a few
    // milliseconds, faster than the resident-set governor looks: building and saving 48 M
    // points under 256M peaked at 752 MiB with it, 432 MiB without. The price: no read-ahead
    // when a page is not in the page cache.
    madvise(memory, bytes, MADV_RANDOM);
    return memory;
}

void unmapScratchFile(void* memory, std::size_t bytes, int fd) {
    munmap(memory, bytes);
    close(fd);
}

void writeScratchFile(int fd, std::uint64_t offset, const void* data, std::size_t bytes) {
    const auto* from = static_cast<const std::uint8_t*>(data);
    while (bytes > 0) {
        const ssize_t written = pwrite(fd, from, bytes, static_cast<off_t>(offset));
        if (written < 0 && errno == EINTR) {
            continue;
        }
        if (written <= 0) {
            throw std::runtime_error(std::string("cannot write sorted points to their scratch "
                                                 "file beyond the memory budget: ") +
                                     std::strerror(errno));
        }
        from += written;
        offset += static_cast<std::uint64_t>(written);
        bytes -= static_cast<std::size_t>(written);
    }
}

void readFileAhead(int fd, std::uint64_t offset, std::uint64_t bytes) {
    constexpr std::uint64_t kHintBytes = std::uint64_t{1} << 20; // under any device's window
    const std::uint64_t end = offset + bytes;
    for (std::uint64_t at = offset; at < end; at += kHintBytes) {
        const std::uint64_t length = std::min(kHintBytes, end - at);
        // Advice: a refusal only costs the read-ahead.
        posix_fadvise(fd, static_cast<off_t>(at), static_cast<off_t>(length),
                      POSIX_FADV_WILLNEED);
    }
}

void dropResidentPages(void* memory, std::size_t bytes) {
    // On a shared file mapping this unmaps the pages only: dirty ones are written back by the
    // kernel, and the next access faults the data back in.
    madvise(memory, bytes, MADV_DONTNEED);
}

} // namespace omicron
