// The deepest level of a version 4 .omh, written while the hierarchy is still being built.
//
// Its columns come right after the level table, so their place depends only on the depth,
// and where every leaf is at the deepest level (leaf collapse off) they are the sorted cloud's
// arrays verbatim: positions, normals, colours, intensities, LAS column, each once, in order.
// A thread follows the sorted prefix as the sorter publishes it and writes each array's
// finished pages from the cloud's own memory with direct I/O: nothing is encoded or copied,
// the page cache is not touched (on a VM whose freed memory goes back to the host, page-cache
// pages are fresh memory to fault in, on the cores the sort needs), and the disk works while
// the cores sort. The save after the build is left with the upper levels (a fifth of the
// records at ratio 0.2), the tables and the footer; writeOmh checks that the finished
// hierarchy's deepest level is the whole cloud in order and writes the columns itself where it
// is not.
//
// Nothing is streamed (finish() hands back an empty result) for a cloud in a scratch file
// (reading it here would fault its pages in behind the budget's back), in the packed store (no
// array is a column), or on a file system without direct I/O (a tmpfs before Linux 6.6: there
// the copy into the page cache would take the sort's cores); writeOmh then writes the columns
// after the build, still without encoding them.
#pragma once

#include "formats/omh_column_sink.hpp"
#include "io/atomic_file_writer.hpp"
#include "points/sorted_cloud.hpp"

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

namespace omicron {

class OmhColumnStream {
public:
    // Starts the thread. `cloud` is asked (from that thread, every millisecond until it
    // answers) for the build's sorted cloud. `file` (nothing written to it yet) must outlive
    // this object; its own writes and this thread's touch different bytes, and writeOmh
    // writes the columns' region only after finish().
    OmhColumnStream(AtomicFileWriter& file, int maxLevel,
                    std::function<std::shared_ptr<const SortedCloud>()> cloud);
    // Stops the thread without waiting for more points (a build that failed or was cancelled).
    ~OmhColumnStream();
    OmhColumnStream(const OmhColumnStream&) = delete;
    OmhColumnStream& operator=(const OmhColumnStream&) = delete;

    // After the build, once the cloud is complete: writes what is published and not yet
    // written, stops the thread and hands over what it wrote (empty when it streamed nothing,
    // or when the cloud ended with another count than it announced). Rethrows the thread's
    // error (an OutputError: a full disk, an I/O error).
    OmhStreamedColumns finish();

    // Bytes written so far (all columns).
    std::uint64_t bytesWritten() const { return m_bytesWritten.load(std::memory_order_relaxed); }

private:
    void run();
    // Whether the cloud's columns can be streamed; if so opens the direct descriptor and
    // reserves the region.
    bool start(const SortedCloud& cloud);
    // Writes column c's bytes [m_done[c], end) (end a multiple of the alignment, or the
    // column's end once the cloud is complete).
    void writeColumn(std::size_t c, std::uint64_t end);
    // pwrite of whole blocks at `at` through the direct descriptor; false where direct I/O
    // turns out to be refused (the stream then stops, streaming nothing).
    bool writeDirect(std::size_t c, const std::uint8_t* bytes, std::uint64_t count,
                     std::uint64_t at);
    // fdatasync: what was written so far reaches persistent storage, during the build rather
    // than at the save's commit.
    void persist();
    [[noreturn]] void fail(const std::string& what, int error) const;

    AtomicFileWriter& m_file;
    std::uint64_t m_offset; // the columns start here
    std::function<std::shared_ptr<const SortedCloud>()> m_source;
    std::shared_ptr<const SortedCloud> m_cloud; // the thread's until finish()
    OmhStreamedColumns m_written;               // the thread's until finish()
    std::vector<const std::uint8_t*> m_data;    // each column's bytes in the cloud
    std::vector<omh::ColumnSpan> m_spans;       // omh::columnSpans for the capacity
    std::vector<std::uint64_t> m_done;          // each column's bytes written
    std::vector<oms::PayloadChecksum> m_checksums;
    std::unique_ptr<std::uint8_t, void (*)(void*)> m_tail{nullptr, std::free}; // a last block
    int m_direct = -1;
    std::uint64_t m_unpersisted = 0; // bytes written since the last persist()
    bool m_streaming = false;
    std::atomic<std::uint64_t> m_bytesWritten{0};
    std::atomic<bool> m_finishing{false}; // write up to the end, then stop
    std::atomic<bool> m_abandon{false};   // stop now
    std::exception_ptr m_error;
    std::thread m_thread;
};

} // namespace omicron
