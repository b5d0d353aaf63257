#include "formats/omh_column_stream.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <new>
#include <system_error>
#include <unistd.h>

namespace omicron {

namespace {

// Each write moves at most this much (the device's queue takes it in pieces anyway).
constexpr std::uint64_t kWriteBytes = std::uint64_t{4} << 20;
// How long the thread sleeps when it has caught up with the sorted prefix: the sorter
// publishes chunks of hundreds of thousands of points, so a millisecond late costs nothing.
constexpr auto kPollInterval = std::chrono::milliseconds(1);
constexpr std::uint64_t kAlign = AtomicFileWriter::kDirectAlignment;
// Direct writes reach the device, not yet its persistent storage, and the extents they fill are
// converted from unwritten in the journal: persisting 363 MB of columns at the commit took
// 0.16-0.18 s after the build on the test VM. The thread persists them as it goes instead,
// this many bytes at a time, while the build runs.
constexpr std::uint64_t kPersistBytes = std::uint64_t{64} << 20;

std::uint64_t columnsOffsetFor(int maxLevel) {
    omh::Header header;
    header.version = omh::kFirstVersionWithDeepestColumns;
    header.setLevelCount(static_cast<std::size_t>(maxLevel) + 1);
    return header.columnsOffset();
}

} // namespace

OmhColumnStream::OmhColumnStream(AtomicFileWriter& file, int maxLevel,
                                 std::function<std::shared_ptr<const SortedCloud>()> cloud)
    : m_file(file), m_offset(columnsOffsetFor(maxLevel)), m_source(std::move(cloud)) {
    m_thread = std::thread([this] { run(); });
}

OmhColumnStream::~OmhColumnStream() {
    m_abandon.store(true);
    if (m_thread.joinable()) {
        m_thread.join();
    }
    if (m_direct >= 0) {
        ::close(m_direct);
    }
}

OmhStreamedColumns OmhColumnStream::finish() {
    m_finishing.store(true);
    m_thread.join();
    if (m_direct >= 0) { // the file has one descriptor again, as any save's
        ::close(m_direct);
        m_direct = -1;
    }
    if (m_error) {
        std::rethrow_exception(m_error);
    }
    if (!m_streaming) {
        return {};
    }
    for (const oms::PayloadChecksum& checksum : m_checksums) {
        m_written.digests.push_back(checksum.digest());
    }
    return std::move(m_written);
}

void OmhColumnStream::run() {
    try {
        while (!m_abandon.load()) {
            // Read before the cloud's end: once the build is over (finishing), the end read
            // after it is the final one, and everything up to it gets written before stopping.
            const bool finishing = m_finishing.load();
            if (!m_cloud) {
                // The uniform columns are declared before the first point is published: the
                // record layout is known once a point is (or the cloud is complete, empty).
                std::shared_ptr<const SortedCloud> cloud = m_source();
                if (cloud && (cloud->sortedEnd() > 0 || cloud->complete())) {
                    m_cloud = std::move(cloud);
                    if (!start(*m_cloud)) {
                        return; // not streamed: writeOmh writes the columns
                    }
                }
            }
            if (!m_cloud) {
                if (finishing) {
                    return;
                }
                std::this_thread::sleep_for(kPollInterval);
                continue;
            }
            const bool complete = m_cloud->complete();
            const std::size_t end = m_cloud->sortedEnd();
            if (complete && end != m_written.points) {
                m_streaming = false; // not the count announced: writeOmh writes the columns
                return;
            }
            bool wrote = false;
            for (std::size_t c = 0; c < m_written.columns.size(); ++c) {
                const std::uint64_t bytes = std::uint64_t{end} * m_written.columns[c].bytes;
                const std::uint64_t target = complete ? bytes : bytes / kAlign * kAlign;
                if (target > m_done[c]) {
                    writeColumn(c, target);
                    wrote = true;
                }
            }
            if (complete) {
                // Every column written to its end; the commit's fsync persists the last bytes
                // with the rest of the file, without holding up the save before it.
                return;
            }
            if (m_unpersisted >= kPersistBytes) {
                persist();
            }
            if (!wrote) {
                if (finishing) {
                    return; // a build that ended without completing the cloud
                }
                std::this_thread::sleep_for(kPollInterval);
            }
        }
    } catch (...) {
        m_error = std::current_exception();
    }
}

bool OmhColumnStream::start(const SortedCloud& cloud) {
    if (cloud.fileBacked() || cloud.order() != CloudOrder::Morton) {
        return false;
    }
    const omh::RecordLayout layout =
        omh::RecordLayout::of(cloud.attributes(), !cloud.attributes().has(Attribute::Normal),
                              omhUniformColumns(cloud), omh::kFirstVersionWithDeepestColumns);
    m_written.columns = omh::recordColumns(layout);
    for (const omh::Column& column : m_written.columns) {
        m_data.push_back(omhCloudColumn(cloud, column));
        if (m_data.back() == nullptr) {
            return false; // the packed store
        }
    }
    m_direct = m_file.openDirect();
    if (m_direct < 0) {
        return false;
    }
    m_written.cloud = &cloud;
    m_written.offset = m_offset;
    m_written.points = cloud.capacity();
    m_spans = omh::columnSpans(m_written.columns, m_written.points);
    const std::uint64_t regionBytes = m_spans.back().end;
    m_done.assign(m_written.columns.size(), 0);
    m_checksums = std::vector<oms::PayloadChecksum>(m_written.columns.size());
    m_tail.reset(static_cast<std::uint8_t*>(std::aligned_alloc(kAlign, kAlign)));
    if (!m_tail) {
        throw std::bad_alloc();
    }
    // The whole region's room at once: a full disk fails here, before the build has gone far.
    // (It makes the file that long; writeOmh cuts it to what it finally holds.)
    m_file.reserve(m_offset, regionBytes, "the deepest level");
    m_streaming = true;
    return true;
}

void OmhColumnStream::writeColumn(std::size_t c, std::uint64_t end) {
    const std::uint8_t* data = m_data[c];
    const std::uint64_t base = m_offset + m_spans[c].begin;
    while (m_done[c] < end && !m_abandon.load()) {
        const std::uint8_t* bytes = data + m_done[c];
        const std::uint64_t whole = (end - m_done[c]) / kAlign * kAlign;
        // The column's last, partial block goes from an aligned copy padded with zeros (the
        // padding before the next column, or bytes writeOmh writes after this).
        const std::uint64_t count = whole > 0 ? std::min(whole, kWriteBytes) : end - m_done[c];
        m_checksums[c].update(bytes, count);
        if (whole == 0) {
            std::memset(m_tail.get(), 0, kAlign);
            std::memcpy(m_tail.get(), bytes, count);
        }
        if (!writeDirect(c, whole > 0 ? bytes : m_tail.get(), whole > 0 ? count : kAlign,
                         base + m_done[c])) {
            return;
        }
        m_done[c] += count;
        m_unpersisted += count;
        m_bytesWritten.fetch_add(count, std::memory_order_relaxed);
    }
}

bool OmhColumnStream::writeDirect(std::size_t c, const std::uint8_t* bytes, std::uint64_t count,
                                  std::uint64_t at) {
    for (std::uint64_t written = 0; written < count;) {
        const ssize_t n =
            ::pwrite(m_direct, bytes + written, count - written, static_cast<off_t>(at + written));
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n < 0 && errno == EINVAL) {
            // Direct I/O refused after all (an alignment the device needs beyond the page's):
            // nothing is streamed, writeOmh writes the columns.
            m_streaming = false;
            m_abandon.store(true);
            return false;
        }
        if (n <= 0) {
            fail("cannot write the deepest level's " +
                     std::string(omh::columnName(m_written.columns[c].kind)) + " column",
                 n < 0 ? errno : EIO);
        }
        written += static_cast<std::uint64_t>(n);
    }
    return true;
}

void OmhColumnStream::persist() {
    if (::fdatasync(m_direct) != 0) {
        fail("cannot persist the deepest level's columns", errno);
    }
    m_unpersisted = 0;
}

void OmhColumnStream::fail(const std::string& what, int error) const {
    throw OutputError(m_file.targetPath() + ": " + what + ": " +
                      std::system_category().message(error));
}

} // namespace omicron
