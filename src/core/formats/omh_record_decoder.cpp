#include "formats/omh_record_decoder.hpp"

#include "formats/omh_reader.hpp"
#include "hex_text.hpp"
#include "io/raw_bytes.hpp"

#include <algorithm>
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

namespace {

// Whether `p` is finite and lies in the cell of the node `nodeCode`, whose level-21 codes are
// shifted right by `shift` (both loaders' check of a stored position).
bool inNodeCell(const glm::vec3& p, morton::Code nodeCode, int shift) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) &&
           (morton::encodeUnit(p.x, p.y, p.z) >> shift) == nodeCode;
}

} // namespace

std::size_t OmhRecordDecoder::store(const std::uint8_t* records, std::size_t count,
                                    std::size_t point, morton::Code nodeCode, int level) const {
    const int shift = 3 * (morton::kMaxLevel - level);
    std::size_t firstBad = count;
    const std::uint8_t* record = records;
    for (std::size_t r = 0; r < count; ++r, record += m_layout.bytes) {
        const std::size_t at = point + r;
        const auto p = loadRaw<glm::vec3>(record);
        if (firstBad == count && !inNodeCell(p, nodeCode, shift)) {
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

namespace {

// Where the cloud keeps a column's values, contiguous (a column in the records is not
// uniform, so the cloud holds one value a point).
std::uint8_t* columnBase(SortedCloud& cloud, omh::ColumnKind kind) {
    const auto bytes = [](auto span) {
        return reinterpret_cast<std::uint8_t*>(span.data());
    };
    switch (kind) {
    case omh::ColumnKind::Position:
        return bytes(cloud.mutablePositions());
    case omh::ColumnKind::Normal:
        return bytes(cloud.mutableNormals());
    case omh::ColumnKind::Color:
        return bytes(cloud.mutableColors());
    case omh::ColumnKind::Intensity:
        return bytes(cloud.mutableIntensities());
    case omh::ColumnKind::Las:
        return bytes(cloud.mutableLasColumn());
    }
    return nullptr;
}

// Columns are read in pieces of at most this many bytes.
constexpr std::size_t kColumnReadBytes = std::size_t{4} << 20;

} // namespace

void OmhRecordDecoder::readColumns(FileStream& stream, int level, std::uint64_t inLevel,
                                   std::size_t count, std::size_t point,
                                   std::vector<oms::PayloadChecksum>* checksums) const {
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    const std::vector<omh::Column> columns = omh::recordColumns(m_layout);
    const std::vector<omh::ColumnSpan> spans = omh::columnSpans(columns, entry.points);
    for (std::size_t c = 0; c < columns.size(); ++c) {
        const std::size_t bytes = columns[c].bytes;
        const std::uint64_t offset = entry.payloadOffset + spans[c].begin + inLevel * bytes;
        std::uint8_t* out = columnBase(m_cloud, columns[c].kind) + point * bytes;
        stream.seek(offset);
        const std::string section = omhSectionAt(m_header, offset);
        for (std::size_t left = count * bytes; left > 0;) {
            const std::size_t take = std::min(left, kColumnReadBytes);
            stream.readExact(out, take, section);
            if (checksums != nullptr) {
                (*checksums)[c].update(out, take);
            }
            out += take;
            left -= take;
        }
    }
}

std::size_t OmhRecordDecoder::firstMisplaced(std::size_t point, std::size_t count,
                                             morton::Code nodeCode, int level) const {
    const int shift = 3 * (morton::kMaxLevel - level);
    const glm::vec3* positions = m_cloud.positions().data() + point;
    for (std::size_t r = 0; r < count; ++r) {
        if (!inNodeCell(positions[r], nodeCode, shift)) {
            return r;
        }
    }
    return count;
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
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    // A columnar level's position is in its first column (the positions).
    const std::uint64_t byte =
        entry.payloadOffset +
        recordInLevel * (m_header.columnar(entry) ? sizeof(glm::vec3) : m_layout.bytes);
    return InputError(InputErrorKind::MalformedValue, m_header.path, InputLocation::byte(byte),
                      "in " + omhSectionAt(m_header, byte) + ", record " +
                          std::to_string(recordInLevel) +
                          ": the position lies outside the cell of its node " + hexText(nodeCode));
}

} // namespace omicron
