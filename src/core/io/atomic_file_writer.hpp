// Writes a file so that the target is either the complete new file or untouched: bytes go to
// a temporary file in the target's folder, commit() flushes, fsyncs and renames it over the
// target. Destroyed without commit() (an error, an exception), the temporary is removed. The
// temporary has no name until commit() (nameless_file.hpp), so a process killed while it
// writes leaves nothing behind; where the file system cannot make nameless files it is
// ".NAME.tmp-TOKEN-PID-XXXXXX" from the start. Such names (and the one a process killed between
// naming its temporary and the rename leaves) are removed by the next writer of the same target
// once their process is gone (leftover_files.hpp).
//
// A big file is persisted while it is written (io/file_flusher.hpp).
#pragma once

#include "io/file_flusher.hpp"
#include "io/scratch_bytes.hpp"
#include "io/write_behind.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace omicron {

// A failure to write an output file; what() names the file and the reason.
class OutputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class AtomicFileWriter {
public:
    explicit AtomicFileWriter(std::string targetPath); // throws OutputError
    ~AtomicFileWriter();
    AtomicFileWriter(const AtomicFileWriter&) = delete;
    AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

    // Buffered; throws OutputError (disk full, I/O error) naming the target.
    void write(const void* data, std::size_t count);
    void write(const std::string& text) { write(text.data(), text.size()); }

    // Overwrites `count` bytes at `offset` of what was written already (offset + count <=
    // bytesWritten()): for fields known only at the end, such as a table of checksums that
    // precedes the data it covers. Throws OutputError.
    void writeAt(std::uint64_t offset, const void* data, std::size_t count);

    // Makes the file `size` bytes long (size >= bytesWritten()), its space reserved on disk
    // at once, so that regions beyond what was written sequentially can be filled with
    // writeAt in any order; write() continues at `size`. A disk without the room is an
    // OutputError naming the bytes needed, before anything is written there. On a tmpfs the
    // free space is checked and the region left sparse (reserving it there would zero its
    // memory serially, before the writers could).
    void extendTo(std::uint64_t size);

    // Reserves bytes [offset, offset + count) of the file on disk (the file becomes at least
    // that long); returns false where the file system cannot reserve, leaving it as it was.
    // No room is an OutputError naming offset + count bytes of `what` ("the file"). On a tmpfs
    // only the free space is checked (false): reserving there would zero the memory serially.
    // Any thread, on a file no other thread resizes meanwhile.
    bool reserve(std::uint64_t offset, std::uint64_t count, const std::string& what) const;

    // Cuts the file to `size` bytes (size <= bytesWritten()): for a file another descriptor
    // (openDirect) made longer than what it finally holds. write() continues at `size`.
    void truncateTo(std::uint64_t size);

    // A second descriptor of the temporary file for direct I/O (O_DIRECT: writes bypass the
    // page cache; offsets, lengths and buffers aligned to kDirectAlignment), for a region
    // that a thread of its own fills; the caller closes it. -1 where the file system refuses
    // direct I/O (a tmpfs before Linux 6.6).
    int openDirect() const;
    static constexpr std::size_t kDirectAlignment = 4096;

    // For regions filled with writeAt: starts writing [offset, offset + count) back to disk
    // (and has the disk persist what it holds of the file: io/file_flusher.hpp), or waits for
    // that and drops it from the page cache (io/write_behind.hpp).
    void startWriteBack(std::uint64_t offset, std::uint64_t count);
    void dropFromCache(std::uint64_t offset, std::uint64_t count);

    std::uint64_t bytesWritten() const { return m_bytesWritten; }
    // How many times the writer's thread has had the disk persist the file so far.
    std::uint64_t backgroundFlushes() const;
    const std::string& targetPath() const { return m_targetPath; }

    // Flushes, fsyncs and renames onto the target; throws OutputError.
    void commit();

private:
    void flushBuffer();
    [[noreturn]] void fail(const std::string& what, int error) const;
    // Gives the nameless temporary its hidden name beside the target, for the rename.
    void nameTemporary();

    std::string m_targetPath;
    std::string m_tempPath; // empty while the temporary has no name
    std::string m_tempPrefix;
    int m_fd = -1;
    ScratchBytes m_buffer; // kBufferBytes from the first write, never zeroed: a file of a few
                           // bytes faults in no more than those
    std::size_t m_buffered = 0;
    std::uint64_t m_bytesWritten = 0;
    std::uint64_t m_onFile = 0;      // bytes handed to write(2)
    WriteBehind m_writeBehind;       // large files: written windows leave the page cache
    // The ranges dropFromCache() was asked to drop, merged where they meet (one per region
    // written front to back), dropped again by commit() once the file is persisted.
    std::vector<std::pair<std::uint64_t, std::uint64_t>> m_dropped;
    bool m_committed = false;
    std::unique_ptr<FileFlusher> m_flusher; // from the first window written back
};

} // namespace omicron
