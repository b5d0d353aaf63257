#include "formats/oms_reader.hpp"

#include "io/input_error.hpp"
#include "io/raw_bytes.hpp"
#include "sort/budgeted_cloud.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace omicron {

namespace {

// Records are read and decoded in blocks of at most this size (and at most one range).
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;

// `digits` hex digits: 16 for checksums and codes, fewer for small fields.
std::string hex(std::uint64_t value, int digits = 16) {
    char text[19];
    std::snprintf(text, sizeof(text), "0x%0*llx", digits, static_cast<unsigned long long>(value));
    return text;
}

// Printable ASCII as is, anything else as \xNN: for showing a wrong magic.
std::string quoteBytes(const std::uint8_t* bytes, std::size_t count) {
    std::string text = "'";
    for (std::size_t i = 0; i < count; ++i) {
        if (std::isprint(bytes[i]) != 0 && bytes[i] != '\\' && bytes[i] != '\'') {
            text += static_cast<char>(bytes[i]);
        } else {
            char escaped[5];
            std::snprintf(escaped, sizeof(escaped), "\\x%02x", bytes[i]);
            text += escaped;
        }
    }
    return text + "'";
}

std::string quoteMagic(const std::array<char, 8>& magic) {
    return quoteBytes(reinterpret_cast<const std::uint8_t*>(magic.data()), magic.size());
}

bool isFinite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::dvec3 loadDvec3(const std::uint8_t* at) {
    return {loadRaw<double>(at), loadRaw<double>(at + 8), loadRaw<double>(at + 16)};
}

std::string lowerExtension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

} // namespace

bool isOmsFile(const std::string& path) {
    if (lowerExtension(path) == ".oms") {
        return true;
    }
    try {
        FileStream stream(path);
        std::array<char, 8> magic{};
        return stream.read(magic.data(), magic.size()) == magic.size() && magic == oms::kMagic;
    } catch (const InputError&) {
        return false;
    }
}

OmsReader::OmsReader(const std::string& path, PointStorage storage, std::uint64_t memoryBudgetBytes,
                     const std::string& tempDir)
    : m_stream(path) {
    namespace h = oms::header;
    const auto error = [&](InputErrorKind kind, std::uint64_t byte, const std::string& detail) {
        return InputError(kind, path, InputLocation::byte(byte), detail);
    };
    const std::uint64_t fileBytes = m_stream.size();
    if (fileBytes == 0) {
        throw InputError(InputErrorKind::EmptyFile, path, InputLocation::none(),
                         "the file is empty (0 bytes), expected a .oms sorted stream");
    }

    std::array<std::uint8_t, oms::kHeaderBytes> header{};
    const std::size_t got = m_stream.read(header.data(), header.size());
    const std::size_t magicBytes = std::min(got, oms::kMagic.size());
    if (std::memcmp(header.data(), oms::kMagic.data(), magicBytes) != 0) {
        throw error(InputErrorKind::UnknownFormat, 0,
                    "expected the .oms magic " + quoteMagic(oms::kMagic) + ", found " +
                        quoteBytes(header.data(), magicBytes));
    }
    if (got < oms::kHeaderBytes) {
        throw error(InputErrorKind::Truncated, fileBytes,
                    "expected a " + std::to_string(oms::kHeaderBytes) +
                        "-byte .oms header, but the file ends at byte " +
                        std::to_string(fileBytes));
    }

    const auto endianness = loadRaw<std::uint32_t>(header.data() + h::kEndianness);
    if (endianness == __builtin_bswap32(oms::kEndiannessMarker)) {
        throw error(InputErrorKind::UnsupportedFeature, h::kEndianness,
                    "the file was written in big-endian byte order (marker bytes 01 02 03 04); "
                    "only little-endian .oms files (04 03 02 01) are supported");
    }
    if (endianness != oms::kEndiannessMarker) {
        throw error(InputErrorKind::MalformedHeader, h::kEndianness,
                    "expected the endianness marker " + hex(oms::kEndiannessMarker, 8) +
                        ", found " + hex(endianness, 8));
    }
    const auto version = loadRaw<std::uint32_t>(header.data() + h::kVersion);
    if (version != oms::kVersion) {
        throw error(InputErrorKind::UnsupportedFeature, h::kVersion,
                    "expected .oms format version " + std::to_string(oms::kVersion) +
                        ", found version " + std::to_string(version));
    }
    const auto storedHeaderChecksum = loadRaw<std::uint64_t>(header.data() + h::kChecksum);
    const std::uint64_t headerChecksum = oms::headerChecksum(header.data());
    if (storedHeaderChecksum != headerChecksum) {
        throw error(InputErrorKind::MalformedHeader, h::kChecksum,
                    "header checksum mismatch: expected the stored XXH64 " +
                        hex(storedHeaderChecksum) + " of bytes 0-" +
                        std::to_string(h::kChecksum - 1) + ", computed " + hex(headerChecksum) +
                        ": the header is damaged");
    }

    const auto sortDepth = loadRaw<std::uint8_t>(header.data() + h::kSortDepth);
    if (sortDepth != oms::kSortDepth) {
        throw error(InputErrorKind::UnsupportedFeature, h::kSortDepth,
                    "expected sort depth " + std::to_string(oms::kSortDepth) + ", found " +
                        std::to_string(sortDepth));
    }
    const auto attributeBits = loadRaw<std::uint8_t>(header.data() + h::kAttributes);
    if ((attributeBits & ~oms::kKnownAttributeBits) != 0) {
        throw error(InputErrorKind::UnsupportedFeature, h::kAttributes,
                    "expected attribute bits within " + hex(oms::kKnownAttributeBits, 2) +
                        " (normal 1, colour 2, intensity 4, LAS 8, GPS time 16, NIR 32), "
                        "found " +
                        hex(attributeBits, 2));
    }
    const auto extraBytes = loadRaw<std::uint16_t>(header.data() + h::kExtraBytes);
    const AttributeSet attributes = AttributeSet::fromBits(attributeBits, extraBytes);
    if (!attributes.valid()) {
        throw error(InputErrorKind::MalformedHeader, h::kAttributes,
                    "attribute bits " + hex(attributeBits, 2) + " with " +
                        std::to_string(extraBytes) +
                        " extra bytes: GPS time, NIR and extra bytes need the LAS bit (8)");
    }
    m_layout = oms::RecordLayout::of(attributes);
    const auto recordBytes = loadRaw<std::uint16_t>(header.data() + h::kRecordBytes);
    if (recordBytes != m_layout.bytes) {
        throw error(InputErrorKind::MalformedHeader, h::kRecordBytes,
                    "expected a record size of " + std::to_string(m_layout.bytes) +
                        " bytes for attribute bits " + hex(attributeBits, 2) + ", found " +
                        std::to_string(recordBytes));
    }
    const auto reservedNonZero = [&](std::size_t begin, std::size_t end) -> std::size_t {
        for (std::size_t at = begin; at < end; ++at) {
            if (header[at] != 0) {
                return at;
            }
        }
        return 0;
    };
    for (const auto& [begin, end] :
         {std::pair{h::kReserved0, h::kCubeOrigin}, std::pair{h::kReserved1, h::kChecksum}}) {
        if (const std::size_t at = reservedNonZero(begin, end); at != 0) {
            throw error(InputErrorKind::MalformedHeader, at,
                        "expected reserved header bytes " + std::to_string(begin) + "-" +
                            std::to_string(end - 1) + " to be zero, found " +
                            std::to_string(header[at]) + " at byte " + std::to_string(at));
        }
    }
    const glm::dvec3 origin = loadDvec3(header.data() + h::kCubeOrigin);
    const auto edge = loadRaw<double>(header.data() + h::kCubeEdge);
    const glm::dvec3 sourceOffset = loadDvec3(header.data() + h::kSourceOffset);
    if (!isFinite(origin)) {
        throw error(InputErrorKind::MalformedHeader, h::kCubeOrigin,
                    "expected a finite cube origin");
    }
    if (!std::isfinite(edge) || !(edge > 0.0)) {
        throw error(InputErrorKind::MalformedHeader, h::kCubeEdge,
                    "expected a finite cube edge > 0, found " + std::to_string(edge));
    }
    if (!isFinite(sourceOffset)) {
        throw error(InputErrorKind::MalformedHeader, h::kSourceOffset,
                    "expected a finite source offset");
    }
    const auto pointCount = loadRaw<std::uint64_t>(header.data() + h::kPointCount);
    if (pointCount == 0) {
        throw error(InputErrorKind::NoPoints, h::kPointCount,
                    "the header declares 0 points, expected at least one");
    }

    // The size must be exactly header + records + footer. Compared without multiplying the
    // count first: a huge declared count must not overflow into a plausible size.
    constexpr std::uint64_t framing = oms::kHeaderBytes + oms::kFooterBytes;
    const std::string declared = "the header declares " + std::to_string(pointCount) +
                                 " records of " + std::to_string(recordBytes) + " bytes";
    if (fileBytes < framing || pointCount > (fileBytes - framing) / recordBytes) {
        const std::uint64_t recordsEnd = pointCount > (UINT64_MAX - framing) / recordBytes
                                             ? UINT64_MAX
                                             : oms::kHeaderBytes + pointCount * recordBytes;
        std::string where;
        if (fileBytes < recordsEnd) {
            const std::uint64_t record = (fileBytes - oms::kHeaderBytes) / recordBytes;
            where = "inside record " + std::to_string(record) + " (which starts at byte " +
                    std::to_string(oms::kHeaderBytes + record * recordBytes) + ")";
        } else {
            where = "inside the " + std::to_string(oms::kFooterBytes) +
                    "-byte footer (which starts at byte " + std::to_string(recordsEnd) + ")";
        }
        throw error(InputErrorKind::Truncated, fileBytes,
                    declared + ", so the file should be " +
                        (recordsEnd == UINT64_MAX
                             ? std::string("larger than 2^64 bytes")
                             : std::to_string(recordsEnd + oms::kFooterBytes) + " bytes") +
                        ", but it ends at byte " + std::to_string(fileBytes) + ", " + where);
    }
    const std::uint64_t footerStart = oms::kHeaderBytes + pointCount * recordBytes;
    const std::uint64_t expectedBytes = footerStart + oms::kFooterBytes;
    if (fileBytes != expectedBytes) {
        throw error(InputErrorKind::CountMismatch, expectedBytes,
                    declared + ", so the file should end with its footer at byte " +
                        std::to_string(expectedBytes) + ", but it has " +
                        std::to_string(fileBytes - expectedBytes) + " more bytes");
    }

    // The footer is checked now, so a damaged one fails before the stream is read.
    namespace f = oms::footer;
    std::array<std::uint8_t, oms::kFooterBytes> footer{};
    m_stream.seek(footerStart);
    m_stream.readExact(footer.data(), footer.size(), "the .oms footer");
    if (std::memcmp(footer.data() + f::kMagic, oms::kFooterMagic.data(),
                    oms::kFooterMagic.size()) != 0) {
        throw error(InputErrorKind::MalformedValue, footerStart + f::kMagic,
                    "expected the footer magic " + quoteMagic(oms::kFooterMagic) + ", found " +
                        quoteBytes(footer.data() + f::kMagic, oms::kFooterMagic.size()));
    }
    const auto footerCount = loadRaw<std::uint64_t>(footer.data() + f::kPointCount);
    if (footerCount != pointCount) {
        throw error(InputErrorKind::CountMismatch, footerStart + f::kPointCount,
                    "the footer's point count " + std::to_string(footerCount) +
                        " differs from the header's " + std::to_string(pointCount));
    }
    m_expectedPayloadChecksum = loadRaw<std::uint64_t>(footer.data() + f::kChecksum);

    m_info.path = path;
    m_info.version = version;
    m_info.pointCount = pointCount;
    m_info.sortDepth = sortDepth;
    m_info.attributes = attributes;
    m_info.recordBytes = recordBytes;
    m_info.fileBytes = fileBytes;
    m_info.cube = CubeTransform{origin, edge};
    m_info.sourceOffset = sourceOffset;
    m_cloud =
        makeSortedCloud(m_info.cube, sourceOffset, attributes, static_cast<std::size_t>(pointCount),
                        storage, memoryBudgetBytes, tempDir);
}

ReadSummary OmsReader::read(const SortedRangeConsumer& consumer, const ReadOptions& options) {
    if (m_readCalled) {
        throw std::logic_error(m_info.path + ": OmsReader::read() called twice");
    }
    m_readCalled = true;
    ReadSummary summary;
    SortedCloud& cloud = *m_cloud;
    const std::size_t count = cloud.capacity();
    const std::size_t recordBytes = m_layout.bytes;
    const std::size_t rangePoints =
        std::max<std::size_t>(1, std::min(options.batchPoints, kBlockBytes / recordBytes));
    const AttributeSet attributes = m_info.attributes;
    oms::PayloadChecksum checksum;
    morton::Code previousCode = 0;

    m_stream.seek(oms::kHeaderBytes);
    for (std::size_t begin = 0; begin < count;) {
        if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) {
            summary.cancelled = true;
            return summary;
        }
        const std::size_t end = std::min(count, begin + rangePoints);
        const std::uint64_t blockStart = oms::kHeaderBytes + std::uint64_t{begin} * recordBytes;
        m_block.resize((end - begin) * recordBytes);
        m_stream.readExact(m_block.data(), m_block.size(),
                           "records " + std::to_string(begin) + " to " + std::to_string(end - 1));
        checksum.update(m_block.data(), m_block.size());
        const std::uint8_t* record = m_block.data();
        const SortedCloud::StagedRange out = cloud.stage(end);
        for (std::size_t i = begin; i < end; ++i, record += recordBytes) {
            const auto p = loadRaw<glm::vec3>(record);
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
                throw InputError(InputErrorKind::MalformedValue, m_info.path,
                                 InputLocation::byte(blockStart + (i - begin) * recordBytes),
                                 "record " + std::to_string(i) +
                                     ": expected a finite position in the unit cube");
            }
            const morton::Code code = morton::encodeUnit(p.x, p.y, p.z);
            if (code < previousCode) {
                const std::uint64_t at = blockStart + (i - begin) * recordBytes;
                throw InputError(
                    InputErrorKind::MalformedValue, m_info.path, InputLocation::byte(at),
                    "record " + std::to_string(i) + " at byte " + std::to_string(at) +
                        " is out of Morton order: the file is not sorted (its "
                        "code " +
                        hex(code) + " is below the previous record's " + hex(previousCode) + ")");
            }
            previousCode = code;
            const std::size_t at = i - begin;
            out.positions[at] = p;
            if (attributes.has(Attribute::Normal)) {
                out.normals[at] = loadRaw<glm::vec3>(record + m_layout.normalOffset);
            }
            if (attributes.has(Attribute::Color)) {
                out.colors[at] = loadRaw<glm::u8vec3>(record + m_layout.colorOffset);
            }
            if (attributes.has(Attribute::Intensity)) {
                out.intensities[at] = loadRaw<std::uint16_t>(record + m_layout.intensityOffset);
            }
            if (m_layout.lasBytes != 0) { // no LAS column: nowhere to copy to
                std::memcpy(out.las.data() + at * m_layout.lasBytes, record + m_layout.lasOffset,
                            m_layout.lasBytes);
            }
        }
        cloud.publish(end);
        consumer(cloud, begin, end);
        summary.pointsDelivered = end;
        ++summary.batches;
        begin = end;
    }

    const std::uint64_t footerStart = oms::kHeaderBytes + std::uint64_t{count} * recordBytes;
    const std::uint64_t payloadChecksum = checksum.digest();
    if (payloadChecksum != m_expectedPayloadChecksum) {
        throw InputError(InputErrorKind::MalformedValue, m_info.path,
                         InputLocation::byte(footerStart + oms::footer::kChecksum),
                         "payload checksum mismatch: the footer stores XXH3-64 " +
                             hex(m_expectedPayloadChecksum) + " for the record bytes " +
                             std::to_string(oms::kHeaderBytes) + "-" +
                             std::to_string(footerStart - 1) + ", they hash to " +
                             hex(payloadChecksum) + ": the records are damaged");
    }
    cloud.markComplete();
    return summary;
}

} // namespace omicron
