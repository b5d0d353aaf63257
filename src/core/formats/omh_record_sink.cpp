#include "formats/omh_record_sink.hpp"

#include "io/raw_bytes.hpp"

#include <algorithm>
#include <cstring>

namespace omicron {

namespace {

// Point records are encoded into a block of about this size before being hashed and written.
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;
// A positional sink starts the write-back of each window it completes and drops the window
// before it from the page cache (the sequential writer's drop-behind, per region).
constexpr std::uint64_t kCacheWindowBytes = std::uint64_t{64} << 20;

} // namespace

OmhRecordSink::OmhRecordSink(AtomicFileWriter& file, const SortedCloud& cloud,
                             const omh::RecordLayout& layout)
    : m_file(file), m_cloud(cloud), m_layout(layout),
      m_block(std::max<std::size_t>(1, kBlockBytes / layout.bytes) * layout.bytes),
      m_checksum(std::make_unique<oms::PayloadChecksum>()) {}

OmhRecordSink::OmhRecordSink(AtomicFileWriter& file, const SortedCloud& cloud,
                             const omh::RecordLayout& layout, std::uint64_t offset)
    : OmhRecordSink(file, cloud, layout) {
    m_positional = true;
    m_regionStart = m_at = offset;
}

void OmhRecordSink::add(std::uint32_t index, std::uint16_t encodedRadius,
                        std::uint32_t estimatedNormal) {
    if (m_used == m_block.size()) {
        flush();
    }
    std::uint8_t* record = m_block.data() + m_used;
    const AttributeSet attributes = m_cloud.attributes();
    storeRaw(record, m_cloud.position(index));
    if (attributes.has(Attribute::Normal)) {
        storeRaw(record + m_layout.point.normalOffset, m_cloud.normals()[index]);
    }
    if (attributes.has(Attribute::Color)) {
        storeRaw(record + m_layout.point.colorOffset, m_cloud.color(index));
    }
    if (attributes.has(Attribute::Intensity)) {
        storeRaw(record + m_layout.point.intensityOffset, m_cloud.intensities()[index]);
    }
    if (m_layout.point.lasBytes != 0) { // no LAS column: no record to copy from
        std::memcpy(record + m_layout.point.lasOffset, m_cloud.lasRecord(index),
                    m_layout.point.lasBytes);
    }
    storeRaw(record + m_layout.radiusOffset, encodedRadius);
    if (m_layout.estimatedNormalOffset != 0) {
        storeRaw(record + m_layout.estimatedNormalOffset, estimatedNormal);
    }
    m_used += m_layout.bytes;
}

void OmhRecordSink::addNode(const OctreeNode& node, const NodeSplats& splats) {
    for (std::uint32_t p = 0; p < node.pointCount; ++p) {
        add(node.heldPoint(p), splats.radii[p], splats.normals.empty() ? 0u : splats.normals[p]);
    }
}

std::uint64_t OmhRecordSink::finishSection() {
    flush();
    if (m_positional && m_at > m_regionStart + m_released) {
        m_file.startWriteBack(m_regionStart + m_released, m_at - m_regionStart - m_released);
    }
    const std::uint64_t digest = m_checksum->digest();
    m_checksum = std::make_unique<oms::PayloadChecksum>();
    return digest;
}

void OmhRecordSink::flush() {
    if (m_used == 0) {
        return;
    }
    m_checksum->update(m_block.data(), m_used);
    if (!m_positional) {
        m_file.write(m_block.data(), m_used);
        m_used = 0;
        return;
    }
    m_file.writeAt(m_at, m_block.data(), m_used);
    m_at += m_used;
    m_used = 0;
    // Two complete windows behind the write position: start the newer's write-back, wait for
    // the older's and drop it. At most two windows of each region stay cached.
    while (m_at - m_regionStart >= m_released + 2 * kCacheWindowBytes) {
        const std::uint64_t older = m_regionStart + m_released;
        m_file.startWriteBack(older + kCacheWindowBytes, kCacheWindowBytes);
        m_file.dropFromCache(older, kCacheWindowBytes);
        m_released += kCacheWindowBytes;
    }
}

} // namespace omicron
