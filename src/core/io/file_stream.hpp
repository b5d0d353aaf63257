// Sequential binary reads from a file with the absolute offset always known, so errors can
// name the byte. Thin wrapper over POSIX read(): callers read in large blocks themselves.
// readAt() reads at an offset without moving the position (pread), from any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace omicron {

class FileStream {
public:
    // Throws InputError: CannotOpen (missing, permissions), NotARegularFile (directory...).
    explicit FileStream(std::string path);
    ~FileStream();
    FileStream(const FileStream&) = delete;
    FileStream& operator=(const FileStream&) = delete;

    const std::string& path() const { return m_path; }
    std::uint64_t size() const { return m_size; }
    std::uint64_t position() const { return m_position; }
    std::uint64_t remaining() const { return m_size - m_position; }

    void seek(std::uint64_t offset);

    // Reads up to `count` bytes; returns fewer only at the end of the file.
    std::size_t read(void* destination, std::size_t count);

    // Reads up to `count` bytes from byte `offset`, leaving position() as it is; returns fewer
    // only at the end of the file. Safe to call from several threads at once.
    std::size_t readAt(std::uint64_t offset, void* destination, std::size_t count) const;

    // Reads exactly `count` bytes or throws Truncated: "expected <what>, the file ends".
    void readExact(void* destination, std::size_t count, const std::string& what);

private:
    std::string m_path;
    int m_fd = -1;
    std::uint64_t m_size = 0;
    std::uint64_t m_position = 0;
};

} // namespace omicron
