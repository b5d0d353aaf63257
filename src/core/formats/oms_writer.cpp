#include "formats/oms_writer.hpp"

#include "io/raw_bytes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace omicron {

namespace {

// Records are encoded into a block of about this size before being hashed and written.
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;

bool isFinite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::array<std::uint8_t, oms::kHeaderBytes>
encodeHeader(const CubeTransform& cube, const glm::dvec3& sourceOffset, AttributeSet attributes,
             std::uint64_t pointCount, const oms::UniformColumns& uniform) {
    namespace h = oms::header;
    std::array<std::uint8_t, oms::kHeaderBytes> bytes{}; // reserved fields stay zero
    std::memcpy(bytes.data() + h::kMagic, oms::kMagic.data(), oms::kMagic.size());
    storeRaw(bytes.data() + h::kVersion, oms::kVersion);
    storeRaw(bytes.data() + h::kEndianness, oms::kEndiannessMarker);
    storeRaw(bytes.data() + h::kPointCount, pointCount);
    storeRaw(bytes.data() + h::kSortDepth, oms::kSortDepth);
    storeRaw(bytes.data() + h::kAttributes, attributes.bits());
    storeRaw(bytes.data() + h::kRecordBytes,
             static_cast<std::uint16_t>(oms::storedRecordLayout(attributes, uniform).bytes));
    storeRaw(bytes.data() + h::kExtraBytes, attributes.extraBytes());
    storeRaw(bytes.data() + h::kUniformColumns, uniform.bits);
    for (int axis = 0; axis < 3; ++axis) {
        storeRaw(bytes.data() + h::kCubeOrigin + 8 * axis, cube.origin[axis]);
        storeRaw(bytes.data() + h::kSourceOffset + 8 * axis, sourceOffset[axis]);
    }
    storeRaw(bytes.data() + h::kCubeEdge, cube.edge);
    if (uniform.intensityUniform()) {
        storeRaw(bytes.data() + h::kUniformIntensity, uniform.intensity);
    }
    if (uniform.lasUniform()) {
        std::memcpy(bytes.data() + h::kUniformLasRecord, uniform.lasRecord.data(),
                    uniform.lasRecord.size());
    }
    storeRaw(bytes.data() + h::kChecksum, oms::headerChecksum(bytes.data()));
    return bytes;
}

// Why `uniform` cannot go with `attributes`, or empty.
std::string uniformColumnsProblem(AttributeSet attributes, const oms::UniformColumns& uniform) {
    if ((uniform.bits & ~(oms::kUniformIntensityBit | oms::kUniformLasBit)) != 0) {
        return "unknown uniform column bits " + std::to_string(uniform.bits);
    }
    if (uniform.intensityUniform() && !attributes.has(Attribute::Intensity)) {
        return "a uniform intensity for a cloud without intensities";
    }
    if (uniform.lasUniform() &&
        (!attributes.has(Attribute::Las) || uniform.lasRecord.size() != attributes.lasBytes() ||
         uniform.lasRecord.size() > oms::kMaxUniformLasBytes)) {
        return "a uniform LAS record of " + std::to_string(uniform.lasRecord.size()) +
               " bytes for a LAS column of " + std::to_string(attributes.lasBytes()) +
               " (at most " + std::to_string(oms::kMaxUniformLasBytes) + " fit the header)";
    }
    return {};
}

} // namespace

OmsWriter::~OmsWriter() = default;

void OmsWriter::fail(const std::string& what) {
    // Dropping the file removes the temporary; the target stays as it was.
    m_file.reset();
    throw OutputError(m_path + ": " + what);
}

void OmsWriter::open(const std::string& path, const CubeTransform& cube,
                     const glm::dvec3& sourceOffset, AttributeSet attributes,
                     std::uint64_t pointCount, const oms::UniformColumns& uniform) {
    m_path = path;
    m_file.reset();
    if (pointCount == 0) {
        fail("a .oms file holds at least one point, got 0");
    }
    if ((attributes.bits() & ~oms::kKnownAttributeBits) != 0 || !attributes.valid()) {
        fail("unknown attribute bits " + std::to_string(attributes.bits()));
    }
    if (const std::string problem = uniformColumnsProblem(attributes, uniform); !problem.empty()) {
        fail(problem);
    }
    if (oms::RecordLayout::of(attributes).bytes > 0xFFFF) {
        fail("a point record of " + std::to_string(oms::RecordLayout::of(attributes).bytes) +
             " bytes (" + std::to_string(attributes.extraBytes()) +
             " LAS extra bytes) exceeds the 65535 a .oms record may hold");
    }
    if (!isFinite(cube.origin) || !isFinite(sourceOffset) || !std::isfinite(cube.edge) ||
        !(cube.edge > 0.0)) {
        fail("the cube origin, cube edge and source offset must be finite and the edge > 0");
    }
    m_file = std::make_unique<AtomicFileWriter>(path);
    m_checksum = std::make_unique<oms::PayloadChecksum>();
    m_layout = oms::storedRecordLayout(attributes, uniform);
    m_attributes = attributes;
    m_uniform = uniform;
    m_pointCount = pointCount;
    m_pointsWritten = 0;
    m_lastCode = 0;
    const auto header = encodeHeader(cube, sourceOffset, attributes, pointCount, uniform);
    m_file->write(header.data(), header.size());
}

void OmsWriter::append(const SortedCloud& cloud, std::size_t begin, std::size_t end) {
    if (!m_file) {
        throw OutputError(m_path + ": OmsWriter::append() without a successful open()");
    }
    if (cloud.attributes() != m_attributes) {
        fail("the appended cloud has attribute bits " + std::to_string(cloud.attributes().bits()) +
             ", the file was opened with " + std::to_string(m_attributes.bits()));
    }
    if (begin != m_pointsWritten || end < begin || end > cloud.sortedEnd()) {
        fail("expected a published range starting at point " + std::to_string(m_pointsWritten) +
             ", got [" + std::to_string(begin) + ", " + std::to_string(end) + ") with " +
             std::to_string(cloud.sortedEnd()) + " points published");
    }
    if (end - begin > m_pointCount - m_pointsWritten) {
        fail("appending [" + std::to_string(begin) + ", " + std::to_string(end) + ") exceeds the " +
             std::to_string(m_pointCount) + " points declared at open()");
    }
    const auto normals = cloud.normals();
    const auto intensities = cloud.intensities();
    const std::size_t recordBytes = m_layout.bytes;
    const std::size_t recordsPerBlock = std::max<std::size_t>(1, kBlockBytes / recordBytes);
    for (std::size_t blockBegin = begin; blockBegin < end;) {
        const std::size_t blockEnd = std::min(end, blockBegin + recordsPerBlock);
        m_block.resize((blockEnd - blockBegin) * recordBytes);
        std::uint8_t* record = m_block.data();
        for (std::size_t i = blockBegin; i < blockEnd; ++i, record += recordBytes) {
            const glm::u8vec3 color =
                m_attributes.has(Attribute::Color) ? cloud.color(i) : glm::u8vec3(0);
            encodeRecord(i, cloud.position(i), normals.empty() ? nullptr : &normals[i], &color,
                         intensities.empty() ? nullptr : &intensities[i],
                         m_attributes.lasBytes() == 0 ? nullptr : cloud.lasRecord(i), record);
        }
        m_checksum->update(m_block.data(), m_block.size());
        m_file->write(m_block.data(), m_block.size());
        blockBegin = blockEnd;
    }
    m_pointsWritten = end;
}

void OmsWriter::append(const PointBatch& sorted) {
    if (!m_file) {
        throw OutputError(m_path + ": OmsWriter::append() without a successful open()");
    }
    if (sorted.attributes != m_attributes) {
        fail("the appended batch has attribute bits " + std::to_string(sorted.attributes.bits()) +
             ", the file was opened with " + std::to_string(m_attributes.bits()));
    }
    if (sorted.size() > m_pointCount - m_pointsWritten) {
        fail("appending " + std::to_string(sorted.size()) + " points after " +
             std::to_string(m_pointsWritten) + " exceeds the " + std::to_string(m_pointCount) +
             " points declared at open()");
    }
    m_block.resize(sorted.size() * m_layout.bytes);
    const std::size_t lasBytes = m_attributes.lasBytes();
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        encodeRecord(m_pointsWritten + i, sorted.positions[i],
                     sorted.normals.empty() ? nullptr : &sorted.normals[i],
                     sorted.colors.empty() ? nullptr : &sorted.colors[i],
                     sorted.intensities.empty() ? nullptr : &sorted.intensities[i],
                     lasBytes == 0 ? nullptr : sorted.las.data() + i * lasBytes,
                     m_block.data() + i * m_layout.bytes);
    }
    m_checksum->update(m_block.data(), m_block.size());
    m_file->write(m_block.data(), m_block.size());
    m_pointsWritten += sorted.size();
}

void OmsWriter::encodeRecord(std::uint64_t index, const glm::vec3& position,
                             const glm::vec3* normal, const glm::u8vec3* color,
                             const std::uint16_t* intensity, const std::uint8_t* las,
                             std::uint8_t* record) {
    // The reader recomputes codes from the stored positions, so that is what must be in order
    // (SortedCloud::code does the same).
    const morton::Code code = morton::encodeUnit(position.x, position.y, position.z);
    if (code < m_lastCode) {
        fail("point " + std::to_string(index) +
             " is out of Morton order: the points are not sorted");
    }
    m_lastCode = code;
    storeRaw(record, position);
    if (m_attributes.has(Attribute::Normal)) {
        storeRaw(record + m_layout.normalOffset, *normal);
    }
    if (m_attributes.has(Attribute::Color)) {
        storeRaw(record + m_layout.colorOffset, *color);
    }
    if (m_layout.intensity) {
        storeRaw(record + m_layout.intensityOffset, *intensity);
    } else if (m_uniform.intensityUniform() && *intensity != m_uniform.intensity) {
        fail("point " + std::to_string(index) + " has intensity " + std::to_string(*intensity) +
             ", not the uniform " + std::to_string(m_uniform.intensity) + " given at open()");
    }
    if (m_layout.lasBytes != 0) {
        std::memcpy(record + m_layout.lasOffset, las, m_layout.lasBytes);
    } else if (m_uniform.lasUniform() &&
               std::memcmp(las, m_uniform.lasRecord.data(), m_uniform.lasRecord.size()) != 0) {
        fail("point " + std::to_string(index) +
             "'s LAS column differs from the uniform record given at open()");
    }
}

void OmsWriter::finish() {
    if (!m_file) {
        throw OutputError(m_path + ": OmsWriter::finish() without a successful open()");
    }
    if (m_pointsWritten != m_pointCount) {
        fail("finish() after " + std::to_string(m_pointsWritten) + " points, expected the " +
             std::to_string(m_pointCount) + " declared at open()");
    }
    namespace f = oms::footer;
    std::array<std::uint8_t, oms::kFooterBytes> footer{};
    std::memcpy(footer.data() + f::kMagic, oms::kFooterMagic.data(), oms::kFooterMagic.size());
    storeRaw(footer.data() + f::kPointCount, m_pointCount);
    storeRaw(footer.data() + f::kChecksum, m_checksum->digest());
    m_file->write(footer.data(), footer.size());
    m_file->commit();
    m_file.reset();
}

void writeOms(const std::string& path, const SortedCloud& cloud, std::size_t pointCount) {
    OmsWriter writer;
    writer.open(path, cloud.cube(), cloud.sourceOffset(), cloud.attributes(), pointCount,
                oms::uniformColumnsOf(cloud));
    writer.append(cloud, 0, pointCount);
    writer.finish();
}

} // namespace omicron
