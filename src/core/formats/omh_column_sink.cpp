#include "formats/omh_column_sink.hpp"

#include "formats/omh_record_sink.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace omicron {

namespace {

// Runs are written in pieces of at most this many bytes per column (the write-behind's and
// a scratch-file cloud's budget checks see each piece).
constexpr std::size_t kPieceBytes = std::size_t{4} << 20;
// A run is written once it holds this many points.
constexpr std::size_t kRunPoints = std::size_t{1} << 20;

bool sameColumns(const std::vector<omh::Column>& a, const std::vector<omh::Column>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                      [](const omh::Column& x, const omh::Column& y) {
                          return x.kind == y.kind && x.bytes == y.bytes;
                      });
}

// Whether the nodes of `level` hold the cloud's points [0, points) in order, a stretch each.
bool holdsCloudInOrder(const Hierarchy& hierarchy, int level, std::uint64_t points) {
    std::uint64_t next = 0;
    for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
        const OctreeNode& node = hierarchy.node(level, i);
        if (!node.holdsRange() || node.coveredBegin != next) {
            return false;
        }
        next += node.pointCount;
    }
    return next == points;
}

} // namespace

const std::uint8_t* omhCloudColumn(const SortedCloud& cloud, const omh::Column& column) {
    const auto bytes = [](auto span) {
        return span.empty() ? nullptr : reinterpret_cast<const std::uint8_t*>(span.data());
    };
    switch (column.kind) {
    case omh::ColumnKind::Position:
        return bytes(cloud.positions());
    case omh::ColumnKind::Normal:
        return bytes(cloud.normals());
    case omh::ColumnKind::Color:
        return bytes(cloud.colors());
    case omh::ColumnKind::Intensity: // in the records: not uniform, one value a point
        return reinterpret_cast<const std::uint8_t*>(cloud.intensities().data);
    case omh::ColumnKind::Las: // uniform but too long for the header: one record for all
        return cloud.lasColumn().stride == column.bytes ? cloud.lasColumn().data : nullptr;
    }
    return nullptr;
}

std::uint8_t omhUniformColumns(const SortedCloud& cloud) {
    std::uint8_t bits = 0;
    if (cloud.uniformIntensities()) {
        bits |= omh::kUniformIntensityBit;
    }
    if (cloud.uniformLasColumn() && cloud.attributes().lasBytes() <= omh::kMaxUniformLasBytes) {
        bits |= omh::kUniformLasBit;
    }
    return bits;
}

OmhColumnSink::OmhColumnSink(AtomicFileWriter& file, const Hierarchy& hierarchy,
                             const omh::Header& header, int level,
                             const OmhStreamedColumns* streamed)
    : m_file(file), m_cloud(hierarchy.cloud()),
      m_sparseOffset(header.sparseSplatsOffset(header.levels[static_cast<std::size_t>(level)])),
      m_estimatedNormal(header.estimatedNormals), m_columns(header.columns()),
      m_checksums(m_columns.size()) {
    const omh::LevelEntry& entry = header.levels[static_cast<std::size_t>(level)];
    m_spans = omh::columnSpans(m_columns, entry.points);
    for (std::size_t c = 0; c < m_columns.size(); ++c) {
        m_spans[c].begin += entry.payloadOffset;
        m_spans[c].end += entry.payloadOffset;
        m_spans[c].paddingEnd += entry.payloadOffset;
        m_at.push_back(m_spans[c].begin);
        m_writeBehind.emplace_back(m_spans[c].begin);
        m_data.push_back(omhCloudColumn(m_cloud, m_columns[c]));
    }
    m_contiguous = std::all_of(m_data.begin(), m_data.end(), [](auto data) { return data; });
    m_streamed = streamed != nullptr && streamed->cloud == &m_cloud &&
                 streamed->offset == entry.payloadOffset && streamed->points == entry.points &&
                 sameColumns(streamed->columns, m_columns) &&
                 holdsCloudInOrder(hierarchy, level, entry.points);
    if (m_streamed) {
        m_streamedDigests = streamed->digests;
    }
}

void OmhColumnSink::addNode(const OctreeNode& node, const NodeSplats& splats) {
    appendOmhSparseSplats(m_sparseSplats, node, splats, m_estimatedNormal);
    if (m_streamed) {
        return;
    }
    const bool contiguous = m_contiguous && node.holdsRange();
    if (contiguous && node.coveredBegin == m_runEnd && m_runEnd - m_runBegin < kRunPoints) {
        m_runEnd += node.pointCount;
        return;
    }
    flushRun();
    if (contiguous) {
        m_runBegin = node.coveredBegin;
        m_runEnd = m_runBegin + node.pointCount;
        return;
    }
    for (std::size_t c = 0; c < m_columns.size(); ++c) { // a sample, or the packed store
        std::uint8_t* out =
            m_gathered.take(std::size_t{node.pointCount} * m_columns[c].bytes).data();
        gather(c, node, out);
        writeColumn(c, out, node.pointCount);
    }
}

std::uint64_t OmhColumnSink::finishSection() {
    std::vector<std::uint64_t> digests = m_streamedDigests;
    if (!m_streamed) {
        flushRun();
        for (std::size_t c = 0; c < m_columns.size(); ++c) {
            if (m_at[c] != m_spans[c].end) {
                throw std::logic_error("the " + std::string(omh::columnName(m_columns[c].kind)) +
                                       " column ends at byte " + std::to_string(m_at[c]) +
                                       ", expected " + std::to_string(m_spans[c].end));
            }
            // Zeros up to the next column (the file may hold a stream's bytes there).
            const std::vector<std::uint8_t> zeros(m_spans[c].paddingEnd - m_spans[c].end, 0);
            if (!zeros.empty()) {
                m_file.writeAt(m_spans[c].end, zeros.data(), zeros.size());
            }
            m_writeBehind[c].finish(m_file, m_spans[c].paddingEnd);
            digests.push_back(m_checksums[c].digest());
        }
    }
    oms::PayloadChecksum sparse;
    if (!m_sparseSplats.empty()) {
        sparse.update(m_sparseSplats.data(), m_sparseSplats.size());
        m_file.writeAt(m_sparseOffset, m_sparseSplats.data(), m_sparseSplats.size());
    }
    digests.push_back(sparse.digest());
    return omh::columnarChecksum(digests);
}

void OmhColumnSink::flushRun() {
    if (m_runEnd > m_runBegin) {
        for (std::size_t c = 0; c < m_columns.size(); ++c) {
            writeColumn(c, m_data[c] + m_runBegin * m_columns[c].bytes, m_runEnd - m_runBegin);
        }
    }
    m_runBegin = m_runEnd = 0;
}

void OmhColumnSink::writeColumn(std::size_t c, const std::uint8_t* bytes, std::size_t count) {
    for (std::size_t left = count * m_columns[c].bytes; left > 0;) {
        const std::size_t take = std::min(left, kPieceBytes);
        m_checksums[c].update(bytes, take);
        m_file.writeAt(m_at[c], bytes, take);
        m_at[c] += take;
        m_writeBehind[c].advance(m_file, m_at[c]);
        m_cloud.keepWithinBudget(); // a scratch-file cloud's pages just read may go
        bytes += take;
        left -= take;
    }
}

void OmhColumnSink::gather(std::size_t c, const OctreeNode& node, std::uint8_t* out) const {
    const std::size_t bytes = m_columns[c].bytes;
    for (std::uint32_t p = 0; p < node.pointCount; ++p, out += bytes) {
        const std::size_t i = node.heldPoint(p);
        switch (m_columns[c].kind) {
        case omh::ColumnKind::Position: {
            const glm::vec3 v = m_cloud.position(i);
            std::memcpy(out, &v, bytes);
            break;
        }
        case omh::ColumnKind::Normal:
            std::memcpy(out, &m_cloud.normals()[i], bytes);
            break;
        case omh::ColumnKind::Color: {
            const glm::u8vec3 v = m_cloud.color(i);
            std::memcpy(out, &v, bytes);
            break;
        }
        case omh::ColumnKind::Intensity:
            std::memcpy(out, &m_cloud.intensities()[i], bytes);
            break;
        case omh::ColumnKind::Las:
            std::memcpy(out, m_cloud.lasRecord(i), bytes);
            break;
        }
    }
}

} // namespace omicron
