#include "formats/omh_record_decoder.hpp"

#include "formats/omh_reader.hpp"
#include "hex_text.hpp"
#include "io/raw_bytes.hpp"

#include <cmath>
#include <cstring>

namespace omicron {

OmhRecordDecoder::OmhRecordDecoder(const omh::Header& header, SortedCloud& cloud,
                                   StoredSplats& splats)
    : m_header(header), m_layout(omh::RecordLayout::of(header.attributes, header.estimatedNormals,
                                                       header.uniformColumns, header.version)),
      // Without the uniform columns: the reader stored their values once.
      m_attributes(m_layout.attributes), m_estimatedNormals(header.estimatedNormals),
      m_cloud(cloud), m_splats(splats) {}

std::size_t OmhRecordDecoder::store(const std::uint8_t* records, std::size_t count,
                                    std::size_t point, morton::Code nodeCode, int level) const {
    const int shift = 3 * (morton::kMaxLevel - level);
    std::size_t firstBad = count;
    const std::uint8_t* record = records;
    for (std::size_t r = 0; r < count; ++r, record += m_layout.bytes) {
        const std::size_t at = point + r;
        const auto p = loadRaw<glm::vec3>(record);
        const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
        if ((!finite || (morton::encodeUnit(p.x, p.y, p.z) >> shift) != nodeCode) &&
            firstBad == count) {
            firstBad = r;
        }
        m_cloud.mutablePositions()[at] = p;
        if (m_attributes.has(Attribute::Normal)) {
            m_cloud.mutableNormals()[at] = loadRaw<glm::vec3>(record + m_layout.point.normalOffset);
        }
        if (m_attributes.has(Attribute::Color)) {
            m_cloud.mutableColors()[at] = loadRaw<glm::u8vec3>(record + m_layout.point.colorOffset);
        }
        if (m_attributes.has(Attribute::Intensity)) {
            m_cloud.mutableIntensities()[at] =
                loadRaw<std::uint16_t>(record + m_layout.point.intensityOffset);
        }
        if (m_layout.point.lasBytes != 0) { // no LAS column: nowhere to copy to
            std::memcpy(m_cloud.mutableLasColumn().data() + at * m_layout.point.lasBytes,
                        record + m_layout.point.lasOffset, m_layout.point.lasBytes);
        }
        if (m_layout.splats) { // before version 3 (from then on, see readSparseSplats)
            m_splats.setEncoded(
                at, loadRaw<std::uint16_t>(record + m_layout.radiusOffset),
                m_estimatedNormals ? loadRaw<std::uint32_t>(record + m_layout.estimatedNormalOffset)
                                   : 0u);
        }
    }
    return firstBad;
}

void OmhRecordDecoder::storeSparseSplats(const std::uint8_t* bytes, std::size_t count,
                                         std::size_t point) const {
    const std::size_t stride = omh::splatBytes(m_estimatedNormals);
    for (std::size_t p = 0; p < count; ++p, bytes += stride) {
        m_splats.setEncoded(
            point + p, loadRaw<std::uint16_t>(bytes),
            m_estimatedNormals ? loadRaw<std::uint32_t>(bytes + sizeof(std::uint16_t)) : 0u);
    }
}

InputError OmhRecordDecoder::misplaced(int level, std::uint64_t recordInLevel,
                                       morton::Code nodeCode) const {
    const std::uint64_t byte = m_header.levels[static_cast<std::size_t>(level)].payloadOffset +
                               recordInLevel * m_layout.bytes;
    return InputError(InputErrorKind::MalformedValue, m_header.path, InputLocation::byte(byte),
                      "in " + omhSectionAt(m_header, byte) + ", record " +
                          std::to_string(recordInLevel) +
                          ": the position lies outside the cell of its node " + hexText(nodeCode));
}

} // namespace omicron
