#include "formats/omh_reader.hpp"

#include "formats/omh_pager.hpp"
#include "formats/omh_record_decoder.hpp"
#include "hex_text.hpp"
#include "io/input_error.hpp"
#include "io/raw_bytes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace omicron {

namespace {

// Point records are read and decoded in blocks of about this size.
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;

bool isFinite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::dvec3 loadDvec3(const std::uint8_t* at) {
    return {loadRaw<double>(at), loadRaw<double>(at + 8), loadRaw<double>(at + 16)};
}

std::string range(std::uint64_t begin, std::uint64_t end) {
    return "bytes " + std::to_string(begin) + "-" + std::to_string(end == 0 ? 0 : end - 1);
}

std::string levelName(int level) {
    return "level " + std::to_string(level);
}

std::uint64_t checksumOf(const std::uint8_t* bytes, std::size_t count) {
    oms::PayloadChecksum checksum;
    checksum.update(bytes, count);
    return checksum.digest();
}

} // namespace

bool isOmhFile(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension == ".omh") {
        return true;
    }
    try {
        FileStream stream(path);
        std::array<char, 8> magic{};
        return stream.read(magic.data(), magic.size()) == magic.size() && magic == omh::kMagic;
    } catch (const InputError&) {
        return false;
    }
}

std::string omhSectionAt(const omh::Header& header, std::uint64_t offset) {
    if (offset < omh::kHeaderBytes) {
        return "the header (" + range(0, omh::kHeaderBytes) + ")";
    }
    if (offset < header.levelTableEnd()) {
        return "the level table (" + range(omh::kHeaderBytes, header.levelTableEnd()) + ")";
    }
    if (header.version >= omh::kFirstVersionWithDeepestColumns && offset < header.columnsOffset()) {
        return "the padding after the level table (" +
               range(header.levelTableEnd(), header.columnsOffset()) + ")";
    }
    for (std::size_t l = 0; l < header.levels.size(); ++l) {
        const omh::LevelEntry& e = header.levels[l];
        const std::uint64_t end = e.nodeTableOffset + e.nodes * omh::kNodeRecordBytes;
        if (offset >= e.nodeTableOffset && offset < end) {
            return "the node table of " + levelName(static_cast<int>(l)) + " (" +
                   range(e.nodeTableOffset, end) + ")";
        }
    }
    for (std::size_t l = 0; l < header.levels.size(); ++l) {
        const omh::LevelEntry& e = header.levels[l];
        const std::uint64_t end = e.payloadOffset + header.recordsBytes(e);
        if (header.columnar(e) && offset >= e.payloadOffset && offset < end) {
            const std::vector<omh::Column> columns = header.columns();
            const std::vector<omh::ColumnSpan> spans = omh::columnSpans(columns, e.points);
            std::size_t c = 0;
            while (offset >= e.payloadOffset + spans[c].paddingEnd) {
                ++c;
            }
            const std::uint64_t begin = e.payloadOffset + spans[c].begin;
            const std::uint64_t columnEnd = e.payloadOffset + spans[c].end;
            const std::string column = std::string(omh::columnName(columns[c].kind)) +
                                       " column of " + levelName(static_cast<int>(l));
            if (offset >= columnEnd) {
                return "the padding after the " + column + " (" +
                       range(columnEnd, e.payloadOffset + spans[c].paddingEnd) + ")";
            }
            return "the " + column + " (" + range(begin, columnEnd) + ")";
        }
        if (offset >= e.payloadOffset && offset < end) {
            return "the point records of " + levelName(static_cast<int>(l)) + " (" +
                   range(e.payloadOffset, end) + ")";
        }
        const std::uint64_t splatsEnd = e.payloadOffset + header.payloadBytes(e);
        if (offset >= end && offset < splatsEnd) {
            return "the sparse nodes' splat attributes of " + levelName(static_cast<int>(l)) +
                   " (" + range(end, splatsEnd) + ")";
        }
    }
    const std::uint64_t footer = header.footerOffset();
    return "the footer (" + range(footer, footer + omh::kFooterBytes) + ")";
}

std::string omhPayloadName(const omh::Header& header, const omh::LevelEntry& level) {
    // A columnar level's checksum covers all its columns: a mismatch cannot say which.
    std::string name =
        header.columnar(level)
            ? "the columns of level " + std::to_string(header.levels.size() - 1) + " (" +
                  range(level.payloadOffset, level.payloadOffset + header.recordsBytes(level)) + ")"
            : omhSectionAt(header, level.payloadOffset);
    if (level.sparsePoints > 0) {
        name += " and " + omhSectionAt(header, header.sparseSplatsOffset(level));
    }
    return name;
}

OmhReader::OmhReader(const std::string& path) : m_stream(path) {
    namespace h = omh::header;
    const auto error = [&](InputErrorKind kind, std::uint64_t byte, const std::string& detail) {
        return InputError(kind, path, InputLocation::byte(byte), detail);
    };
    const std::uint64_t fileBytes = m_stream.size();
    if (fileBytes == 0) {
        throw InputError(InputErrorKind::EmptyFile, path, InputLocation::none(),
                         "the file is empty (0 bytes), expected a .omh hierarchy file");
    }
    std::array<std::uint8_t, omh::kHeaderBytes> header{};
    const std::size_t got = m_stream.read(header.data(), header.size());
    if (std::memcmp(header.data(), omh::kMagic.data(), std::min(got, omh::kMagic.size())) != 0) {
        throw error(InputErrorKind::UnknownFormat, 0,
                    "in the header: expected the .omh magic 'OMICRONH'");
    }
    if (got < omh::kHeaderBytes) {
        throw error(InputErrorKind::Truncated, fileBytes,
                    "the file ends inside the header (" + range(0, omh::kHeaderBytes) +
                        "), expected " + std::to_string(omh::kHeaderBytes) + " header bytes");
    }
    const auto endianness = loadRaw<std::uint32_t>(header.data() + h::kEndianness);
    if (endianness == __builtin_bswap32(omh::kEndiannessMarker)) {
        throw error(InputErrorKind::UnsupportedFeature, h::kEndianness,
                    "in the header: the file was written in big-endian byte order; only "
                    "little-endian .omh files are supported");
    }
    if (endianness != omh::kEndiannessMarker) {
        throw error(InputErrorKind::MalformedHeader, h::kEndianness,
                    "in the header: expected the endianness marker bytes 04 03 02 01");
    }
    const auto version = loadRaw<std::uint32_t>(header.data() + h::kVersion);
    if (version < omh::kOldestVersion || version > omh::kVersion) {
        throw error(InputErrorKind::UnsupportedFeature, h::kVersion,
                    "in the header: expected .omh format version " +
                        std::to_string(omh::kOldestVersion) + " to " +
                        std::to_string(omh::kVersion) + ", found " + std::to_string(version));
    }
    const auto storedChecksum = loadRaw<std::uint64_t>(header.data() + h::kChecksum);
    const std::uint64_t headerChecksum = omh::smallChecksum(header.data(), h::kChecksum);
    if (storedChecksum != headerChecksum) {
        throw error(InputErrorKind::MalformedHeader, h::kChecksum,
                    "header checksum mismatch: the header stores XXH64 " + hexText(storedChecksum) +
                        " for bytes 0-" + std::to_string(h::kChecksum - 1) + ", they hash to " +
                        hexText(headerChecksum) + ": the header is damaged");
    }

    // The checksum matched, so what follows can only fail for a file that a writer other than
    // omicron's made wrongly: still checked, so nothing below trusts a field blindly.
    const auto malformed = [&](std::size_t byte, const std::string& detail) {
        return error(InputErrorKind::MalformedHeader, byte, "in the header: " + detail);
    };
    omh::Header& info = m_header;
    info.path = path;
    info.version = version;
    info.fileBytes = fileBytes;
    info.totalNodes = loadRaw<std::uint64_t>(header.data() + h::kTotalNodes);
    info.totalPoints = loadRaw<std::uint64_t>(header.data() + h::kTotalPoints);
    info.build.inputPoints = loadRaw<std::uint64_t>(header.data() + h::kInputPoints);
    info.build.droppedPoints = loadRaw<std::uint64_t>(header.data() + h::kDroppedPoints);
    info.build.collapsedLeaves = loadRaw<std::uint64_t>(header.data() + h::kCollapsedLeaves);
    const int maxLevel = header[h::kMaxLevel];
    if (maxLevel < 1 || maxLevel > morton::kMaxLevel) {
        throw malformed(h::kMaxLevel,
                        "expected a depth of 1-21, found " + std::to_string(maxLevel));
    }
    info.build.maxLevel = maxLevel;
    if (header[h::kLevelCount] != maxLevel + 1) {
        throw malformed(h::kLevelCount, "expected " + std::to_string(maxLevel + 1) +
                                            " levels for depth " + std::to_string(maxLevel));
    }
    switch (header[h::kCollapse]) {
    case 0:
        info.build.collapse = LeafCollapse::Off;
        break;
    case 1:
        info.build.collapse = LeafCollapse::Lossless;
        break;
    case 2:
        info.build.collapse = LeafCollapse::Paper;
        break;
    default:
        throw malformed(h::kCollapse, "expected leaf collapse 0, 1 or 2");
    }
    const std::uint8_t attributeBits = header[h::kAttributes];
    if ((attributeBits & ~omh::kKnownAttributeBits) != 0) {
        throw malformed(h::kAttributes, "unknown attribute bits");
    }
    info.attributes = AttributeSet::fromBits(
        attributeBits, loadRaw<std::uint16_t>(header.data() + h::kExtraBytes));
    if (!info.attributes.valid()) {
        throw malformed(h::kExtraBytes, "GPS time, NIR and extra bytes need the LAS attribute bit");
    }
    const std::uint8_t splatBits = header[h::kSplatBits];
    // The builder estimates normals exactly when the cloud has none of its own.
    const bool expectedEstimate = !info.attributes.has(Attribute::Normal);
    if (splatBits != (expectedEstimate ? omh::kSplatEstimatedNormal : 0)) {
        throw malformed(h::kSplatBits,
                        "expected splat bits " + std::to_string(expectedEstimate ? 1 : 0) +
                            " for these attributes, found " + std::to_string(splatBits));
    }
    info.estimatedNormals = expectedEstimate;
    // Uniform columns (version 2; the bytes are zero in version 1, checked below).
    std::size_t reservedFrom = h::kUniformColumns;
    if (version >= 2) {
        const std::uint8_t uniform = header[h::kUniformColumns];
        if ((uniform & ~(omh::kUniformIntensityBit | omh::kUniformLasBit)) != 0) {
            throw malformed(h::kUniformColumns, "unknown uniform column bits");
        }
        if ((uniform & omh::kUniformIntensityBit) != 0 &&
            !info.attributes.has(Attribute::Intensity)) {
            throw malformed(h::kUniformColumns,
                            "a uniform intensity is declared, but the cloud has no intensities");
        }
        const std::size_t lasBytes = info.attributes.lasBytes();
        if ((uniform & omh::kUniformLasBit) != 0 &&
            (lasBytes == 0 || lasBytes > omh::kMaxUniformLasBytes)) {
            throw malformed(h::kUniformColumns,
                            "a uniform LAS column is declared, but the cloud's LAS records are " +
                                std::to_string(lasBytes) + " bytes (expected 1-" +
                                std::to_string(omh::kMaxUniformLasBytes) + ")");
        }
        info.uniformColumns = uniform;
        info.uniformIntensity = loadRaw<std::uint16_t>(header.data() + h::kUniformIntensity);
        if ((uniform & omh::kUniformIntensityBit) == 0 && info.uniformIntensity != 0) {
            throw malformed(h::kUniformIntensity, "expected zero: the intensity is not uniform");
        }
        reservedFrom = h::kUniformLasRecord;
        if ((uniform & omh::kUniformLasBit) != 0) {
            info.uniformLasRecord.assign(header.data() + h::kUniformLasRecord,
                                         header.data() + h::kUniformLasRecord + lasBytes);
            reservedFrom += lasBytes;
        }
        if (header[h::kReserved2] != 0) {
            throw malformed(h::kReserved2, "expected a reserved zero byte");
        }
    }
    m_layout =
        omh::RecordLayout::of(info.attributes, info.estimatedNormals, info.uniformColumns, version);
    info.recordBytes = loadRaw<std::uint16_t>(header.data() + h::kRecordBytes);
    if (info.recordBytes != m_layout.bytes) {
        throw malformed(h::kRecordBytes, "expected a record size of " +
                                             std::to_string(m_layout.bytes) + " bytes, found " +
                                             std::to_string(info.recordBytes));
    }
    for (std::size_t at : {h::kReserved0}) {
        if (header[at] != 0) {
            throw malformed(at, "expected a reserved zero byte");
        }
    }
    for (std::size_t at = reservedFrom; at < h::kChecksum; ++at) {
        if (header[at] != 0) {
            throw malformed(at, "expected reserved bytes " + std::to_string(reservedFrom) + "-" +
                                    std::to_string(h::kChecksum - 1) + " to be zero");
        }
    }
    info.build.ratio = loadRaw<double>(header.data() + h::kRatio);
    if (!(info.build.ratio > 0.0 && info.build.ratio <= 1.0)) {
        throw malformed(h::kRatio, "expected a ratio in (0, 1]");
    }
    info.cube = CubeTransform{loadDvec3(header.data() + h::kCubeOrigin),
                              loadRaw<double>(header.data() + h::kCubeEdge)};
    info.sourceOffset = loadDvec3(header.data() + h::kSourceOffset);
    if (!isFinite(info.cube.origin) || !isFinite(info.sourceOffset)) {
        throw malformed(h::kCubeOrigin, "expected a finite cube origin and source offset");
    }
    if (!std::isfinite(info.cube.edge) || !(info.cube.edge > 0.0)) {
        throw malformed(h::kCubeEdge, "expected a finite cube edge > 0");
    }
    if (info.totalNodes == 0 || info.totalPoints < info.totalNodes) {
        throw malformed(h::kTotalNodes, "expected at least one node and a point per node");
    }

    // Level table.
    const std::size_t levelCount = static_cast<std::size_t>(maxLevel) + 1;
    const std::size_t entryStride = omh::levelEntryBytes(version);
    const std::uint64_t tableBytes = levelCount * entryStride + 8;
    if (fileBytes < omh::kHeaderBytes + tableBytes) {
        throw error(InputErrorKind::Truncated, fileBytes,
                    "the file ends inside the level table (" +
                        range(omh::kHeaderBytes, omh::kHeaderBytes + tableBytes) + ")");
    }
    std::vector<std::uint8_t> table(tableBytes);
    m_stream.readExact(table.data(), table.size(), "the level table");
    const std::uint64_t entryBytes = levelCount * entryStride;
    const auto storedTableChecksum = loadRaw<std::uint64_t>(table.data() + entryBytes);
    const std::uint64_t tableChecksum = omh::smallChecksum(table.data(), entryBytes);
    if (storedTableChecksum != tableChecksum) {
        throw error(
            InputErrorKind::MalformedHeader, omh::kHeaderBytes + entryBytes,
            "level table checksum mismatch: it stores XXH64 " + hexText(storedTableChecksum) +
                " for " + range(omh::kHeaderBytes, omh::kHeaderBytes + entryBytes) +
                ", they hash to " + hexText(tableChecksum) + ": the level table is damaged");
    }
    info.setLevelCount(levelCount);
    std::uint64_t nodes = 0, points = 0;
    for (std::size_t l = 0; l < levelCount; ++l) {
        const std::uint8_t* at = table.data() + l * entryStride;
        omh::LevelEntry& e = info.levels[l];
        e.nodes = loadRaw<std::uint64_t>(at + omh::level::kNodes);
        e.leaves = loadRaw<std::uint64_t>(at + omh::level::kLeaves);
        e.points = loadRaw<std::uint64_t>(at + omh::level::kPoints);
        e.nodeTableOffset = loadRaw<std::uint64_t>(at + omh::level::kNodeTableOffset);
        e.payloadOffset = loadRaw<std::uint64_t>(at + omh::level::kPayloadOffset);
        e.nodeChecksum = loadRaw<std::uint64_t>(at + omh::level::kNodeChecksum);
        e.payloadChecksum = loadRaw<std::uint64_t>(at + omh::level::kPayloadChecksum);
        if (!info.splatsInRecords()) {
            e.sparsePoints = loadRaw<std::uint64_t>(at + omh::level::kSparsePoints);
        }
        const std::uint64_t byte = omh::kHeaderBytes + l * entryStride;
        const auto bad = [&](const std::string& detail) {
            return error(InputErrorKind::MalformedHeader, byte,
                         "in the level table, " + levelName(static_cast<int>(l)) + ": " + detail);
        };
        const std::uint64_t cells = l * 3 < 63 ? std::uint64_t{1} << (3 * l) : UINT64_MAX;
        if ((l == 0 && e.nodes != 1) || e.nodes > cells || e.leaves > e.nodes ||
            e.points < e.nodes || e.nodes > info.totalNodes - nodes ||
            e.points > info.totalPoints - points || e.sparsePoints > e.points) {
            throw bad("the counts (" + std::to_string(e.nodes) + " nodes, " +
                      std::to_string(e.leaves) + " leaves, " + std::to_string(e.points) +
                      " points, " + std::to_string(e.sparsePoints) +
                      " of sparse nodes) do not fit the header's totals and the octree");
        }
        nodes += e.nodes;
        points += e.points;
    }
    if (nodes != info.totalNodes || points != info.totalPoints) {
        throw error(InputErrorKind::CountMismatch, omh::kHeaderBytes,
                    "the level table sums to " + std::to_string(nodes) + " nodes and " +
                        std::to_string(points) + " points, the header declares " +
                        std::to_string(info.totalNodes) + " and " +
                        std::to_string(info.totalPoints));
    }
    // The totals are bounded by the file size before any offset is computed from them.
    const std::uint64_t fixed = info.levelTableEnd() + omh::kFooterBytes;
    if (fileBytes < fixed || info.totalNodes > (fileBytes - fixed) / omh::kNodeRecordBytes ||
        info.totalPoints >
            (fileBytes - fixed - info.totalNodes * omh::kNodeRecordBytes) / info.recordBytes) {
        throw error(InputErrorKind::Truncated, fileBytes,
                    "the file ends at byte " + std::to_string(fileBytes) + ", inside " +
                        omhSectionAt(info, fileBytes) + "; the header declares " +
                        std::to_string(info.totalNodes) + " nodes and " +
                        std::to_string(info.totalPoints) + " point records of " +
                        std::to_string(info.recordBytes) + " bytes");
    }
    // Every section where the counts put it (version 4: the deepest level's columns first).
    omh::Header planned = info;
    omh::assignOffsets(planned);
    for (std::size_t l = 0; l < levelCount; ++l) {
        const auto misplaced = [&](std::size_t field, const std::string& what, std::uint64_t at) {
            return error(InputErrorKind::MalformedHeader,
                         omh::kHeaderBytes + l * entryStride + field,
                         "in the level table, " + levelName(static_cast<int>(l)) + ": expected " +
                             what + " at byte " + std::to_string(at));
        };
        if (info.levels[l].nodeTableOffset != planned.levels[l].nodeTableOffset) {
            throw misplaced(omh::level::kNodeTableOffset, "the node table",
                            planned.levels[l].nodeTableOffset);
        }
        if (info.levels[l].payloadOffset != planned.levels[l].payloadOffset) {
            throw misplaced(omh::level::kPayloadOffset, "the point records",
                            planned.levels[l].payloadOffset);
        }
    }
    const std::uint64_t expectedBytes = info.footerOffset() + omh::kFooterBytes;
    if (fileBytes < expectedBytes) { // version 3: inside a level's sparse splats or the footer
        throw error(InputErrorKind::Truncated, fileBytes,
                    "the file ends at byte " + std::to_string(fileBytes) + ", inside " +
                        omhSectionAt(info, fileBytes) + "; the level table declares " +
                        std::to_string(expectedBytes) + " bytes");
    }
    if (fileBytes != expectedBytes) {
        throw error(InputErrorKind::CountMismatch, expectedBytes,
                    "the file should end with its footer at byte " + std::to_string(expectedBytes) +
                        ", but it has " + std::to_string(fileBytes - expectedBytes) +
                        " more bytes");
    }

    // Footer.
    std::array<std::uint8_t, omh::kFooterBytes> footer{};
    const std::uint64_t footerStart = info.footerOffset();
    m_stream.seek(footerStart);
    m_stream.readExact(footer.data(), footer.size(), "the footer");
    if (std::memcmp(footer.data(), omh::kFooterMagic.data(), omh::kFooterMagic.size()) != 0) {
        throw error(InputErrorKind::MalformedValue, footerStart,
                    "in the footer: expected the footer magic 'OMHEND\\x00\\x00'");
    }
    const auto storedFooterChecksum =
        loadRaw<std::uint64_t>(footer.data() + omh::footer::kChecksum);
    if (storedFooterChecksum != omh::smallChecksum(footer.data(), omh::footer::kChecksum)) {
        throw error(InputErrorKind::MalformedValue, footerStart + omh::footer::kChecksum,
                    "footer checksum mismatch: the footer is damaged");
    }
    if (loadRaw<std::uint64_t>(footer.data() + omh::footer::kTotalNodes) != info.totalNodes ||
        loadRaw<std::uint64_t>(footer.data() + omh::footer::kTotalPoints) != info.totalPoints) {
        throw error(InputErrorKind::CountMismatch, footerStart + omh::footer::kTotalNodes,
                    "the footer's node and point counts differ from the header's");
    }
    if (version >= omh::kFirstVersionWithDeepestColumns) {
        checkPadding(info.levelTableEnd(), info.columnsOffset());
    }
}

void OmhReader::checkPadding(std::uint64_t begin, std::uint64_t end) {
    std::array<std::uint8_t, omh::kColumnAlignment> bytes{};
    const std::size_t count = static_cast<std::size_t>(end - begin); // < kColumnAlignment
    if (m_stream.readAt(begin, bytes.data(), count) != count) {
        throw InputError(InputErrorKind::Truncated, m_header.path, InputLocation::byte(begin),
                         "the file ends inside " + omhSectionAt(m_header, begin));
    }
    for (std::size_t i = 0; i < count; ++i) {
        if (bytes[i] != 0) {
            throw InputError(InputErrorKind::MalformedValue, m_header.path,
                             InputLocation::byte(begin + i),
                             "in " + omhSectionAt(m_header, begin + i) +
                                 ": expected zero bytes, found " + std::to_string(bytes[i]));
        }
    }
}

void OmhReader::checkColumnarChecksum(const omh::LevelEntry& entry,
                                      const std::vector<std::uint64_t>& digests) const {
    const std::uint64_t digest = omh::columnarChecksum(digests);
    if (digest != entry.payloadChecksum) {
        throw InputError(InputErrorKind::MalformedValue, m_header.path,
                         InputLocation::byte(entry.payloadOffset),
                         "checksum mismatch in " + omhPayloadName(m_header, entry) +
                             ": the level table stores XXH3-64 " + hexText(entry.payloadChecksum) +
                             ", the bytes hash to " + hexText(digest));
    }
}

void OmhReader::checkColumnPadding(const omh::LevelEntry& entry) {
    for (const omh::ColumnSpan& span : omh::columnSpans(m_header.columns(), entry.points)) {
        checkPadding(entry.payloadOffset + span.end, entry.payloadOffset + span.paddingEnd);
    }
}

void OmhReader::createHierarchy() {
    std::call_once(m_created, [this] {
        if (m_header.totalPoints > UINT32_MAX) {
            throw InputError(InputErrorKind::UnsupportedFeature, m_header.path,
                             InputLocation::byte(omh::header::kTotalPoints),
                             "the file holds " + std::to_string(m_header.totalPoints) +
                                 " point records; a loaded hierarchy indexes at most 2^32 - 1");
        }
        m_cloud = std::make_shared<SortedCloud>(
            m_header.cube, m_header.sourceOffset, m_header.attributes,
            static_cast<std::size_t>(m_header.totalPoints), CloudOrder::NodeOrder,
            PointStorage::Exact, pagedOnDemand() ? PageSize::Small : PageSize::Huge);
        if (m_header.uniformColumns != 0) {
            m_cloud->setUniformColumns((m_header.uniformColumns & omh::kUniformIntensityBit) != 0
                                           ? &m_header.uniformIntensity
                                           : nullptr,
                                       (m_header.uniformColumns & omh::kUniformLasBit) != 0
                                           ? m_header.uniformLasRecord.data()
                                           : nullptr);
        }
        m_hierarchy = std::make_shared<Hierarchy>(
            m_cloud, m_header.build.maxLevel,
            m_header.splatsInRecords() ? SplatSource::Stored : SplatSource::StoredForSparseNodes);
        if (pagedOnDemand()) {
            m_hierarchy->setResidency(
                std::make_unique<OmhPager>(m_header, m_cloud, *m_hierarchy, m_pagedBudget));
        }
    });
}

void OmhReader::pageOnDemand(std::uint64_t budgetBytes) {
    if (m_hierarchy) {
        throw std::logic_error(m_header.path + ": OmhReader::pageOnDemand() after hierarchy()");
    }
    m_pagedBudget = std::max<std::uint64_t>(budgetBytes, 1);
}

std::uint64_t OmhReader::residentBytesOfAllPoints() const {
    return m_header.totalPoints * OmhPager::residentBytesPerPoint(m_header);
}

std::shared_ptr<const Hierarchy> OmhReader::hierarchy() {
    createHierarchy();
    return m_hierarchy;
}

std::vector<OctreeNode> OmhReader::readNodes(int level, std::vector<std::uint8_t>& childMasks,
                                             std::vector<morton::Code>& expectedCodes,
                                             std::uint64_t firstPoint) {
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    const std::string section = omhSectionAt(m_header, entry.nodeTableOffset);
    m_block.resize(entry.nodes * omh::kNodeRecordBytes);
    m_stream.seek(entry.nodeTableOffset);
    m_stream.readExact(m_block.data(), m_block.size(), section);
    const std::uint64_t checksum = checksumOf(m_block.data(), m_block.size());
    if (checksum != entry.nodeChecksum) {
        throw InputError(InputErrorKind::MalformedValue, m_header.path,
                         InputLocation::byte(entry.nodeTableOffset),
                         "checksum mismatch in " + section + ": the level table stores XXH3-64 " +
                             hexText(entry.nodeChecksum) + ", the records hash to " +
                             hexText(checksum));
    }
    // Level 0 is the root; every deeper level holds exactly the children its parents' masks
    // announce, in Morton order (what the builder's arenas hold).
    if (level == 0) {
        expectedCodes.assign(1, morton::kRoot);
    }
    if (expectedCodes.size() != entry.nodes) {
        throw InputError(InputErrorKind::CountMismatch, m_header.path,
                         InputLocation::byte(entry.nodeTableOffset),
                         "in " + section + ": the child masks of " + levelName(level - 1) +
                             " announce " + std::to_string(expectedCodes.size()) +
                             " nodes, the level table declares " + std::to_string(entry.nodes));
    }
    std::vector<OctreeNode> nodes(entry.nodes);
    std::vector<morton::Code> nextCodes;
    childMasks.assign(entry.nodes, 0);
    std::uint64_t leaves = 0, points = 0, sparsePoints = 0;
    std::uint32_t nextChild = 0;
    for (std::size_t i = 0; i < entry.nodes; ++i) {
        const std::uint8_t* record = m_block.data() + i * omh::kNodeRecordBytes;
        const std::uint64_t byte = entry.nodeTableOffset + i * omh::kNodeRecordBytes;
        const auto bad = [&](std::size_t field, const std::string& detail) {
            return InputError(InputErrorKind::MalformedValue, m_header.path,
                              InputLocation::byte(byte + field),
                              "in " + section + ", node " + std::to_string(i) + ": " + detail);
        };
        OctreeNode& node = nodes[i];
        node.code = loadRaw<std::uint64_t>(record + omh::node::kCode);
        if (node.code != expectedCodes[i]) {
            throw bad(omh::node::kCode, "expected code " + hexText(expectedCodes[i]) +
                                            " (announced by its parent's child mask), found " +
                                            hexText(node.code));
        }
        const auto first = loadRaw<std::uint64_t>(record + omh::node::kFirstPoint);
        if (first != firstPoint + points) {
            throw bad(omh::node::kFirstPoint, "expected its points to start at record " +
                                                  std::to_string(firstPoint + points));
        }
        const auto count = loadRaw<std::uint64_t>(record + omh::node::kPointCount);
        if (count == 0 || count > entry.points - points) {
            throw bad(omh::node::kPointCount, "expected 1 to " +
                                                  std::to_string(entry.points - points) +
                                                  " points, found " + std::to_string(count));
        }
        node.splatScale = loadRaw<float>(record + omh::node::kSplatScale);
        if (!std::isfinite(node.splatScale) || !(node.splatScale > 0.0f)) {
            throw bad(omh::node::kSplatScale, "expected a finite splat scale > 0");
        }
        const std::uint8_t mask = record[omh::node::kChildMask];
        node.flags = record[omh::node::kFlags];
        if ((node.flags & ~omh::kKnownNodeFlags) != 0 || node.isLeaf() != (mask == 0) ||
            (node.has(NodeFlag::Collapsed) &&
             !(node.isLeaf() && level == m_header.build.maxLevel - 1)) ||
            (level == m_header.build.maxLevel && !node.isLeaf())) {
            throw bad(omh::node::kFlags, "flags " + std::to_string(node.flags) +
                                             " and child mask " + std::to_string(mask) +
                                             " contradict each other or the level");
        }
        if (loadRaw<std::uint16_t>(record + omh::node::kReserved) != 0) {
            throw bad(omh::node::kReserved, "expected reserved zero bytes");
        }
        node.sampleIndices = nullptr;
        node.coveredBegin = static_cast<std::uint32_t>(firstPoint + points);
        node.pointCount = static_cast<std::uint32_t>(count);
        node.coveredCount = node.pointCount;
        node.childCount = static_cast<std::uint8_t>(std::popcount(mask));
        node.firstChild = node.childCount > 0 ? nextChild : 0; // a leaf's is 0, as built
        nextChild += node.childCount;
        childMasks[i] = mask;
        for (unsigned octant = 0; octant < 8; ++octant) {
            if ((mask & (1u << octant)) != 0) {
                nextCodes.push_back(morton::child(node.code, octant));
            }
        }
        leaves += node.isLeaf() ? 1 : 0;
        points += count;
        sparsePoints += !m_header.splatsInRecords() && omh::storesSplats(count) ? count : 0;
    }
    if (leaves != entry.leaves || points != entry.points) {
        throw InputError(InputErrorKind::CountMismatch, m_header.path,
                         InputLocation::byte(entry.nodeTableOffset),
                         "in " + section + ": the nodes hold " + std::to_string(leaves) +
                             " leaves and " + std::to_string(points) +
                             " points, the level table declares " + std::to_string(entry.leaves) +
                             " and " + std::to_string(entry.points));
    }
    if (sparsePoints != entry.sparsePoints) {
        throw InputError(InputErrorKind::CountMismatch, m_header.path,
                         InputLocation::byte(entry.nodeTableOffset),
                         "in " + section + ": the nodes of fewer than " +
                             std::to_string(kMinPointsPerSplatEstimate) + " points hold " +
                             std::to_string(sparsePoints) + " points, the level table declares " +
                             std::to_string(entry.sparsePoints));
    }
    expectedCodes = std::move(nextCodes);
    return nodes;
}

void OmhReader::readColumnarPoints(int level, const std::vector<OctreeNode>& nodes,
                                   std::uint64_t firstPoint) {
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    const OmhRecordDecoder decoder(m_header, *m_cloud, m_hierarchy->mutableStoredSplats());
    std::vector<oms::PayloadChecksum> columns(m_header.columns().size());
    decoder.readColumns(m_stream, level, 0, static_cast<std::size_t>(entry.points),
                        static_cast<std::size_t>(firstPoint), &columns);
    oms::PayloadChecksum sparse;
    readSparseSplats(level, nodes, decoder, sparse);
    std::vector<std::uint64_t> digests;
    for (const oms::PayloadChecksum& column : columns) {
        digests.push_back(column.digest());
    }
    digests.push_back(sparse.digest());
    checkColumnarChecksum(entry, digests);
    // Checked after the checksum, as the records are: in a damaged file the mismatch is the
    // better explanation.
    checkColumnPadding(entry);
    for (const OctreeNode& node : nodes) {
        const std::size_t bad =
            decoder.firstMisplaced(node.coveredBegin, node.pointCount, node.code, level);
        if (bad != node.pointCount) {
            throw decoder.misplaced(level, node.coveredBegin + bad - firstPoint, node.code);
        }
    }
}

void OmhReader::readPoints(int level, const std::vector<OctreeNode>& nodes,
                           std::uint64_t firstPoint) {
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    if (m_header.columnar(entry)) {
        return readColumnarPoints(level, nodes, firstPoint);
    }
    const std::string section = omhSectionAt(m_header, entry.payloadOffset);
    const std::string payload = omhPayloadName(m_header, entry);
    const std::size_t recordBytes = m_layout.bytes;
    const std::size_t blockRecords = std::max<std::size_t>(1, kBlockBytes / recordBytes);
    const OmhRecordDecoder decoder(m_header, *m_cloud, m_hierarchy->mutableStoredSplats());
    oms::PayloadChecksum checksum;
    // A point that breaks a rule is reported only after the checksum matched: in a damaged
    // file the checksum mismatch is the better explanation.
    std::optional<InputError> firstProblem;
    std::size_t nodeIndex = 0;
    std::uint64_t nodeBegin = 0; // the current node's first record in the level
    m_stream.seek(entry.payloadOffset);
    for (std::uint64_t begin = 0; begin < entry.points;) {
        const std::size_t count =
            static_cast<std::size_t>(std::min<std::uint64_t>(blockRecords, entry.points - begin));
        m_block.resize(count * recordBytes);
        m_stream.readExact(m_block.data(), m_block.size(), section);
        checksum.update(m_block.data(), m_block.size());
        // The block's records node by node.
        for (std::size_t r = 0; r < count;) {
            while (begin + r >= nodeBegin + nodes[nodeIndex].pointCount) {
                nodeBegin += nodes[nodeIndex++].pointCount;
            }
            const OctreeNode& node = nodes[nodeIndex];
            const std::size_t run = static_cast<std::size_t>(
                std::min<std::uint64_t>(count - r, nodeBegin + node.pointCount - (begin + r)));
            const std::uint64_t inLevel = begin + r;
            const std::size_t bad =
                decoder.store(m_block.data() + r * recordBytes, run,
                              static_cast<std::size_t>(firstPoint + inLevel), node.code, level);
            if (bad != run && !firstProblem) {
                firstProblem = decoder.misplaced(level, inLevel + bad, node.code);
            }
            r += run;
        }
        begin += count;
    }
    readSparseSplats(level, nodes, decoder, checksum);
    const std::uint64_t digest = checksum.digest();
    if (digest != entry.payloadChecksum) {
        throw InputError(InputErrorKind::MalformedValue, m_header.path,
                         InputLocation::byte(entry.payloadOffset),
                         "checksum mismatch in " + payload + ": the level table stores XXH3-64 " +
                             hexText(entry.payloadChecksum) + ", they hash to " + hexText(digest));
    }
    if (firstProblem) {
        throw *firstProblem;
    }
}

void OmhReader::readSparseSplats(int level, const std::vector<OctreeNode>& nodes,
                                 const OmhRecordDecoder& decoder, oms::PayloadChecksum& checksum) {
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    if (entry.sparsePoints == 0) {
        return;
    }
    const std::string section = omhSectionAt(m_header, m_header.sparseSplatsOffset(entry));
    m_stream.seek(m_header.sparseSplatsOffset(entry)); // a columnar level's are aligned
    const std::size_t splatBytes = m_header.splatBytes();
    const std::size_t blockPoints = kBlockBytes / splatBytes;
    auto node = nodes.begin();
    std::uint32_t inNode = 0; // the next point of *node
    for (std::uint64_t begin = 0; begin < entry.sparsePoints;) {
        const std::size_t count = static_cast<std::size_t>(
            std::min<std::uint64_t>(blockPoints, entry.sparsePoints - begin));
        m_block.resize(count * splatBytes);
        m_stream.readExact(m_block.data(), m_block.size(), section);
        checksum.update(m_block.data(), m_block.size());
        // The block's attributes, sparse node by sparse node (readNodes counted them).
        for (std::size_t p = 0; p < count;) {
            while (!omh::storesSplats(node->pointCount)) {
                ++node;
            }
            const std::size_t run = std::min<std::size_t>(count - p, node->pointCount - inNode);
            decoder.storeSparseSplats(m_block.data() + p * splatBytes, run,
                                      node->coveredBegin + inNode);
            p += run;
            inNode += static_cast<std::uint32_t>(run);
            if (inNode == node->pointCount) {
                ++node;
                inNode = 0;
            }
        }
        begin += count;
    }
}

void OmhReader::load(const LevelCallback& onLevel, const std::atomic<bool>* cancel) {
    if (m_loadCalled) {
        throw std::logic_error(m_header.path + ": OmhReader::load() called twice");
    }
    m_loadCalled = true;
    createHierarchy();
    // Complete before anything is published: every node that appears is final, so a front
    // treats all of them as settled (Hierarchy::isSettled).
    m_hierarchy->markComplete();
    std::vector<std::uint8_t> childMasks;
    std::vector<morton::Code> expectedCodes;
    std::uint64_t firstPoint = 0;
    for (int level = 0; level <= m_header.build.maxLevel; ++level) {
        if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) {
            return;
        }
        const std::vector<OctreeNode> nodes =
            readNodes(level, childMasks, expectedCodes, firstPoint);
        if (!pagedOnDemand()) {
            readPoints(level, nodes, firstPoint);
        }
        for (const OctreeNode& node : nodes) {
            m_hierarchy->appendNode(level, node);
        }
        firstPoint += m_header.levels[static_cast<std::size_t>(level)].points;
        if (!pagedOnDemand()) {
            // A paged cloud is never published as a prefix: the pager says what is resident.
            m_cloud->publish(static_cast<std::size_t>(firstPoint));
        }
        m_hierarchy->publishNodes(level);
        if (onLevel) {
            onLevel(level);
        }
    }
    if (!expectedCodes.empty()) {
        throw InputError(InputErrorKind::MalformedValue, m_header.path,
                         InputLocation::byte(m_header.levels.back().nodeTableOffset),
                         "in the node table of the deepest level: nodes announce children below "
                         "the hierarchy's depth");
    }
    if (!pagedOnDemand()) {
        m_cloud->markComplete();
    }
}

void OmhReader::verify() {
    const auto hashRange = [&](std::uint64_t offset, std::uint64_t bytes,
                               const std::string& section) {
        oms::PayloadChecksum checksum;
        m_stream.seek(offset);
        for (std::uint64_t done = 0; done < bytes;) {
            const std::size_t take =
                static_cast<std::size_t>(std::min<std::uint64_t>(kBlockBytes, bytes - done));
            m_block.resize(take);
            m_stream.readExact(m_block.data(), take, section);
            checksum.update(m_block.data(), take);
            done += take;
        }
        return checksum.digest();
    };
    const auto check = [&](std::uint64_t offset, std::uint64_t bytes, std::uint64_t expected,
                           const std::string& section) {
        const std::uint64_t digest = hashRange(offset, bytes, section);
        if (digest != expected) {
            throw InputError(InputErrorKind::MalformedValue, m_header.path,
                             InputLocation::byte(offset),
                             "checksum mismatch in " + section +
                                 ": the level table stores "
                                 "XXH3-64 " +
                                 hexText(expected) + ", the bytes hash to " + hexText(digest));
        }
    };
    // Header, level table and footer were verified at open.
    for (const omh::LevelEntry& e : m_header.levels) {
        check(e.nodeTableOffset, e.nodes * omh::kNodeRecordBytes, e.nodeChecksum,
              omhSectionAt(m_header, e.nodeTableOffset));
    }
    for (const omh::LevelEntry& e : m_header.levels) {
        if (!m_header.columnar(e)) {
            check(e.payloadOffset, m_header.payloadBytes(e), e.payloadChecksum,
                  omhPayloadName(m_header, e));
            continue;
        }
        // Each column hashed on its own, then the sparse splat attributes (columnarChecksum).
        std::vector<std::uint64_t> digests;
        for (const omh::ColumnSpan& span : omh::columnSpans(m_header.columns(), e.points)) {
            const std::uint64_t begin = e.payloadOffset + span.begin;
            digests.push_back(
                hashRange(begin, span.end - span.begin, omhSectionAt(m_header, begin)));
        }
        const std::uint64_t sparse = m_header.sparseSplatsOffset(e);
        digests.push_back(
            hashRange(sparse, e.sparsePoints * m_header.splatBytes(), omhPayloadName(m_header, e)));
        checkColumnarChecksum(e, digests);
        checkColumnPadding(e);
    }
}

} // namespace omicron
