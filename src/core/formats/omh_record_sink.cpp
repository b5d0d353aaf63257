#include "formats/omh_record_sink.hpp"

#include "io/raw_bytes.hpp"

#include <algorithm>
#include <cstring>

namespace omicron {

namespace {

// Point records are encoded into a block of about this size before being hashed and written.
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;

} // namespace

OmhRecordSink::OmhRecordSink(AtomicFileWriter& file, const SortedCloud& cloud,
                             const omh::RecordLayout& layout)
    : m_file(file), m_cloud(cloud), m_layout(layout),
      m_checksum(std::make_unique<oms::PayloadChecksum>()) {}

OmhRecordSink::OmhRecordSink(AtomicFileWriter& file, const SortedCloud& cloud,
                             const omh::RecordLayout& layout, std::uint64_t offset)
    : OmhRecordSink(file, cloud, layout) {
    m_positional = true;
    m_at = offset;
    m_writeBehind = WriteBehind(offset);
}

namespace {

// One point record. `LasBytes` is the LAS column's width when known at compile time (0: read
// from the layout), so that the column's copy is a few moves rather than a library call per
// record (as in the sorter's gather).
template <std::size_t LasBytes = 0>
void encodeRecord(const SortedCloud& cloud, const omh::RecordLayout& layout, std::uint32_t index,
                  std::uint16_t encodedRadius, std::uint32_t estimatedNormal,
                  std::uint8_t* record) {
    const AttributeSet attributes = layout.attributes; // without the uniform columns
    storeRaw(record, cloud.position(index));
    if (attributes.has(Attribute::Normal)) {
        storeRaw(record + layout.point.normalOffset, cloud.normals()[index]);
    }
    if (attributes.has(Attribute::Color)) {
        storeRaw(record + layout.point.colorOffset, cloud.color(index));
    }
    if (attributes.has(Attribute::Intensity)) {
        storeRaw(record + layout.point.intensityOffset, cloud.intensities()[index]);
    }
    const std::size_t lasBytes = LasBytes != 0 ? LasBytes : layout.point.lasBytes;
    if (lasBytes != 0) { // no LAS column: no record to copy from
        std::memcpy(record + layout.point.lasOffset, cloud.lasRecord(index), lasBytes);
    }
    if (layout.splats) {
        storeRaw(record + layout.radiusOffset, encodedRadius);
    }
    if (layout.estimatedNormalOffset != 0) {
        storeRaw(record + layout.estimatedNormalOffset, estimatedNormal);
    }
}

// The exact store's records with every column's base and offset in a local: stores through
// the byte pointer may alias anything, so reading them through the cloud and the layout made
// the compiler load them again for every record (encodeOmhRecords was 6.6 % of a 24.2 M-point
// `build --save`). `heldAt(p)` is the cloud index of the node's p-th held point.
template <std::size_t LasBytes, typename HeldAt>
void encodeExactRecords(const SortedCloud& cloud, const omh::RecordLayout& layout, HeldAt heldAt,
                        const NodeSplats& splats, std::uint32_t first, std::uint32_t last,
                        std::uint8_t* out) {
    const AttributeSet attributes = layout.attributes; // without the uniform columns
    const glm::vec3* const positions = cloud.positions().data();
    const glm::vec3* const normals =
        attributes.has(Attribute::Normal) ? cloud.normals().data() : nullptr;
    const glm::u8vec3* const colors =
        attributes.has(Attribute::Color) ? cloud.colors().data() : nullptr;
    // Intensities and LAS records by their stride: 0 for a uniform column.
    const std::uint16_t* const intensities =
        attributes.has(Attribute::Intensity) ? cloud.intensities().data : nullptr;
    const std::size_t intensityStride = cloud.intensities().stride;
    const std::size_t lasBytes = LasBytes != 0 ? LasBytes : layout.point.lasBytes;
    const std::uint8_t* const las = lasBytes != 0 ? cloud.lasColumn().data : nullptr;
    const std::size_t lasStride = cloud.lasColumn().stride;
    const std::uint16_t* const radii = layout.splats ? splats.radii.data() : nullptr;
    const std::uint32_t* const estimated = splats.normals.empty() ? nullptr : splats.normals.data();
    const std::size_t recordBytes = layout.bytes;
    const std::size_t normalOffset = layout.point.normalOffset;
    const std::size_t colorOffset = layout.point.colorOffset;
    const std::size_t intensityOffset = layout.point.intensityOffset;
    const std::size_t lasOffset = layout.point.lasOffset;
    const std::size_t radiusOffset = layout.radiusOffset;
    const std::size_t estimatedOffset = layout.estimatedNormalOffset;
    for (std::uint32_t p = first; p < last; ++p, out += recordBytes) {
        const std::size_t index = heldAt(p);
        storeRaw(out, positions[index]);
        if (normals != nullptr) {
            storeRaw(out + normalOffset, normals[index]);
        }
        if (colors != nullptr) {
            storeRaw(out + colorOffset, colors[index]);
        }
        if (intensities != nullptr) {
            storeRaw(out + intensityOffset, intensities[index * intensityStride]);
        }
        if (las != nullptr) {
            std::memcpy(out + lasOffset, las + index * lasStride, lasBytes);
        }
        if (radii != nullptr) {
            storeRaw(out + radiusOffset, radii[p]);
        }
        if (estimatedOffset != 0) {
            storeRaw(out + estimatedOffset, estimated != nullptr ? estimated[p] : 0u);
        }
    }
}

template <std::size_t LasBytes>
void encodeRecords(const SortedCloud& cloud, const omh::RecordLayout& layout,
                   const OctreeNode& node, const NodeSplats& splats, std::uint32_t first,
                   std::uint32_t last, std::uint8_t* out) {
    if (cloud.positions().empty()) { // the packed store decodes a point at a time anyway
        for (std::uint32_t p = first; p < last; ++p, out += layout.bytes) {
            encodeRecord<LasBytes>(cloud, layout, node.heldPoint(p),
                                   layout.splats ? splats.radii[p] : std::uint16_t{0},
                                   layout.estimatedNormalOffset != 0 && !splats.normals.empty()
                                       ? splats.normals[p]
                                       : 0u,
                                   out);
        }
        return;
    }
    if (node.holdsRange()) { // the leaves: most records
        const std::uint32_t begin = node.coveredBegin;
        return encodeExactRecords<LasBytes>(
            cloud, layout, [begin](std::uint32_t p) { return begin + p; }, splats, first, last,
            out);
    }
    encodeExactRecords<LasBytes>(
        cloud, layout, [&node](std::uint32_t p) { return node.heldPoint(p); }, splats, first, last,
        out);
}

} // namespace

void encodeOmhRecords(const SortedCloud& cloud, const omh::RecordLayout& layout,
                      const OctreeNode& node, const NodeSplats& splats, std::uint32_t first,
                      std::uint32_t last, std::uint8_t* out) {
    switch (layout.point.lasBytes) { // the LAS column of formats 0/2, 1/3-7/9 and 8/10
    case 8:
        return encodeRecords<8>(cloud, layout, node, splats, first, last, out);
    case 16:
        return encodeRecords<16>(cloud, layout, node, splats, first, last, out);
    case 18:
        return encodeRecords<18>(cloud, layout, node, splats, first, last, out);
    default:
        return encodeRecords<0>(cloud, layout, node, splats, first, last, out);
    }
}

void OmhRecordSink::add(std::uint32_t index, std::uint16_t encodedRadius,
                        std::uint32_t estimatedNormal) {
    if (m_used == m_blockBytes) {
        flush();
        if (m_blockBytes == 0) { // first use: a sink fed only encoded blocks never needs it
            m_blockBytes = std::max<std::size_t>(1, kBlockBytes / m_layout.bytes) * m_layout.bytes;
        }
    }
    encodeRecord(m_cloud, m_layout, index, encodedRadius, estimatedNormal,
                 m_block.take(m_blockBytes).data() + m_used);
    m_used += m_layout.bytes;
}

void OmhRecordSink::addNode(const OctreeNode& node, const NodeSplats& splats) {
    const bool inRecords = m_layout.splats;
    for (std::uint32_t p = 0; p < node.pointCount; ++p) {
        add(node.heldPoint(p), inRecords ? splats.radii[p] : std::uint16_t{0},
            inRecords && !splats.normals.empty() ? splats.normals[p] : 0u);
    }
    addSparseSplats(node, splats);
}

void appendOmhSparseSplats(std::vector<std::uint8_t>& out, const OctreeNode& node,
                           const NodeSplats& splats, bool estimatedNormal) {
    if (!omh::storesSplats(node.pointCount)) {
        return;
    }
    const std::size_t bytes = omh::splatBytes(estimatedNormal);
    const std::size_t at = out.size();
    out.resize(at + node.pointCount * bytes);
    std::uint8_t* to = out.data() + at;
    for (std::uint32_t p = 0; p < node.pointCount; ++p, to += bytes) {
        storeRaw(to, splats.radii[p]);
        if (estimatedNormal) {
            storeRaw(to + sizeof(std::uint16_t), splats.normals.empty() ? 0u : splats.normals[p]);
        }
    }
}

void OmhRecordSink::addSparseSplats(const OctreeNode& node, const NodeSplats& splats) {
    if (!m_layout.splats) {
        appendOmhSparseSplats(m_sparseSplats, node, splats, m_layout.estimatedNormal);
    }
}

void OmhRecordSink::addEncoded(const std::uint8_t* records, std::size_t bytes) {
    flush();
    write(records, bytes);
}

std::uint64_t OmhRecordSink::finishSection() {
    flush();
    write(m_sparseSplats.data(), m_sparseSplats.size()); // version 3: after the records
    m_sparseSplats.clear();
    if (m_positional) {
        m_writeBehind.finish(m_file, m_at);
    }
    const std::uint64_t digest = m_checksum->digest();
    m_checksum = std::make_unique<oms::PayloadChecksum>();
    return digest;
}

void OmhRecordSink::flush() {
    write(m_block.take(m_used).data(), m_used);
    m_used = 0;
}

void OmhRecordSink::write(const std::uint8_t* records, std::size_t bytes) {
    if (bytes == 0) {
        return;
    }
    m_checksum->update(records, bytes);
    if (!m_positional) {
        m_file.write(records, bytes);
        return;
    }
    m_file.writeAt(m_at, records, bytes);
    m_at += bytes;
    m_writeBehind.advance(m_file, m_at);
}

} // namespace omicron
