// Scratch space for clouds larger than memory: the sorter's runs, as files without a name
// (nameless_file.hpp) in the folder the user chose (--temp-dir, the app's setting, else
// $TMPDIR or /tmp). The kernel frees each when its ScratchFile closes it, or when the process
// ends however it ends (SIGKILL, a crash, the out-of-memory killer): no run outlives its
// pipeline, and nothing there is ours to clean up.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace omicron {

class ScratchFolder {
public:
    // `parent` empty: defaultParent(). Throws OutputError naming the folder when no file can
    // be made there (no such folder, no permission).
    explicit ScratchFolder(const std::string& parent);
    ScratchFolder(const ScratchFolder&) = delete;
    ScratchFolder& operator=(const ScratchFolder&) = delete;

    const std::string& parent() const { return m_parent; }

    // Bytes its file system has free for us (statvfs), UINT64_MAX when it cannot tell.
    std::uint64_t freeBytes() const;

    // What the runs of this cloud need in all, for the message of a failed write.
    void setBytesNeeded(std::uint64_t bytes) { m_bytesNeeded = bytes; }
    std::uint64_t bytesNeeded() const { return m_bytesNeeded; }
    std::uint64_t bytesWritten() const { return m_bytesWritten; }

    // Where scratch goes when the user chose nothing: $TMPDIR, else /tmp.
    static std::string defaultParent();

private:
    friend class ScratchFile;
    // A write failed (full disk, quota, I/O error): an OutputError naming the folder the user
    // chose, the bytes needed and written, and what to do.
    [[noreturn]] void failWrite(const std::string& file, int error) const;

    std::string m_parent;
    std::uint64_t m_bytesNeeded = 0;
    std::uint64_t m_bytesWritten = 0;
};

// One file in a ScratchFolder, written front to back, then read by offset from any thread.
// `name` only labels it in messages: the file has none.
class ScratchFile {
public:
    ScratchFile(ScratchFolder& folder, const std::string& name); // throws OutputError
    ~ScratchFile();
    ScratchFile(const ScratchFile&) = delete;
    ScratchFile& operator=(const ScratchFile&) = delete;

    void write(const void* data, std::size_t count); // appends; throws OutputError
    // Reads exactly `count` bytes at `offset`; throws std::runtime_error naming the file.
    void read(std::uint64_t offset, void* data, std::size_t count) const;
    // Bytes [offset, offset + count) will be read soon (readFileAhead: call it from a thread
    // that has nothing else to do).
    void willRead(std::uint64_t offset, std::uint64_t count) const;
    std::uint64_t size() const { return m_size; }

private:
    ScratchFolder& m_folder;
    std::string m_name;
    int m_fd = -1;
    std::uint64_t m_size = 0;
};

} // namespace omicron
