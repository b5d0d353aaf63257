#include "formats/oms_reader.hpp"

#include "formats/oms_record_decoder.hpp"
#include "hex_text.hpp"
#include "io/input_error.hpp"
#include "io/raw_bytes.hpp"
#include "sort/budgeted_cloud.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <vector>

namespace omicron {

namespace {

// Records are read and decoded in blocks of at most this size (and at most one range).
constexpr std::size_t kBlockBytes = std::size_t{4} << 20;

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

// The first of header bytes [begin, end) that is not zero.
std::optional<std::size_t> firstNonZero(const std::array<std::uint8_t, oms::kHeaderBytes>& header,
                                        std::size_t begin, std::size_t end) {
    for (std::size_t at = begin; at < end; ++at) {
        if (header[at] != 0) {
            return at;
        }
    }
    return std::nullopt;
}

// The uniform columns of a version 2 header (version 1: none, its fields reserved zeros),
// checked against the attributes; unused bytes of those fields must be zero.
oms::UniformColumns parseUniformColumns(const std::array<std::uint8_t, oms::kHeaderBytes>& header,
                                        std::uint32_t version, AttributeSet attributes,
                                        const std::string& path) {
    namespace h = oms::header;
    const auto malformed = [&](std::size_t at, const std::string& detail) {
        return InputError(InputErrorKind::MalformedHeader, path, InputLocation::byte(at), detail);
    };
    oms::UniformColumns uniform;
    if (version >= 2) {
        uniform.bits = header[h::kUniformColumns];
    }
    if ((uniform.bits & ~(oms::kUniformIntensityBit | oms::kUniformLasBit)) != 0) {
        throw malformed(h::kUniformColumns,
                        "expected uniform column bits within 0x03 (intensity 1, LAS column 2), "
                        "found " +
                            hexText(uniform.bits, 2));
    }
    if (uniform.intensityUniform() && !attributes.has(Attribute::Intensity)) {
        throw malformed(h::kUniformColumns,
                        "the uniform column bits declare a uniform intensity, but the attribute "
                        "bits have no intensity");
    }
    const std::size_t lasBytes = attributes.lasBytes();
    if (uniform.lasUniform() && (lasBytes == 0 || lasBytes > oms::kMaxUniformLasBytes)) {
        throw malformed(h::kUniformColumns,
                        "the uniform column bits declare a uniform LAS column, but the attribute "
                        "bits give a LAS column of " +
                            std::to_string(lasBytes) + " bytes (1 to " +
                            std::to_string(oms::kMaxUniformLasBytes) + " fit the header)");
    }
    // Zero: the byte after the bits (version 1: the bits too), an intensity or LAS record not
    // declared, the bytes after the LAS record.
    const std::size_t usedEnd = uniform.lasUniform()         ? h::kUniformLasRecord + lasBytes
                                : uniform.intensityUniform() ? h::kUniformLasRecord
                                                             : h::kUniformIntensity;
    std::vector<std::pair<std::size_t, std::size_t>> zeros{
        {version >= 2 ? h::kReserved0 : h::kUniformColumns, h::kCubeOrigin},
        {usedEnd, h::kChecksum}};
    if (uniform.lasUniform() && !uniform.intensityUniform()) {
        zeros.emplace_back(h::kUniformIntensity, h::kUniformLasRecord);
    }
    for (const auto& [begin, end] : zeros) {
        if (const auto at = firstNonZero(header, begin, end)) {
            throw malformed(*at, "expected reserved header bytes " + std::to_string(begin) + "-" +
                                     std::to_string(end - 1) + " to be zero, found " +
                                     std::to_string(header[*at]) + " at byte " +
                                     std::to_string(*at));
        }
    }
    if (uniform.intensityUniform()) {
        uniform.intensity = loadRaw<std::uint16_t>(header.data() + h::kUniformIntensity);
    }
    if (uniform.lasUniform()) {
        uniform.lasRecord.assign(header.data() + h::kUniformLasRecord,
                                 header.data() + h::kUniformLasRecord + lasBytes);
    }
    return uniform;
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
                    "expected the endianness marker " + hexText(oms::kEndiannessMarker, 8) +
                        ", found " + hexText(endianness, 8));
    }
    const auto version = loadRaw<std::uint32_t>(header.data() + h::kVersion);
    if (version < oms::kOldestVersion || version > oms::kVersion) {
        throw error(InputErrorKind::UnsupportedFeature, h::kVersion,
                    "expected .oms format version " + std::to_string(oms::kOldestVersion) + " to " +
                        std::to_string(oms::kVersion) + ", found version " +
                        std::to_string(version));
    }
    const auto storedHeaderChecksum = loadRaw<std::uint64_t>(header.data() + h::kChecksum);
    const std::uint64_t headerChecksum = oms::headerChecksum(header.data());
    if (storedHeaderChecksum != headerChecksum) {
        throw error(InputErrorKind::MalformedHeader, h::kChecksum,
                    "header checksum mismatch: expected the stored XXH64 " +
                        hexText(storedHeaderChecksum) + " of bytes 0-" +
                        std::to_string(h::kChecksum - 1) + ", computed " + hexText(headerChecksum) +
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
                    "expected attribute bits within " + hexText(oms::kKnownAttributeBits, 2) +
                        " (normal 1, colour 2, intensity 4, LAS 8, GPS time 16, NIR 32), "
                        "found " +
                        hexText(attributeBits, 2));
    }
    const auto extraBytes = loadRaw<std::uint16_t>(header.data() + h::kExtraBytes);
    const AttributeSet attributes = AttributeSet::fromBits(attributeBits, extraBytes);
    if (!attributes.valid()) {
        throw error(InputErrorKind::MalformedHeader, h::kAttributes,
                    "attribute bits " + hexText(attributeBits, 2) + " with " +
                        std::to_string(extraBytes) +
                        " extra bytes: GPS time, NIR and extra bytes need the LAS bit (8)");
    }
    const oms::UniformColumns uniform = parseUniformColumns(header, version, attributes, path);
    m_layout = oms::storedRecordLayout(attributes, uniform);
    const auto recordBytes = loadRaw<std::uint16_t>(header.data() + h::kRecordBytes);
    if (recordBytes != m_layout.bytes) {
        throw error(InputErrorKind::MalformedHeader, h::kRecordBytes,
                    "expected a record size of " + std::to_string(m_layout.bytes) +
                        " bytes for attribute bits " + hexText(attributeBits, 2) +
                        (uniform.bits != 0 ? " and uniform column bits " + hexText(uniform.bits, 2)
                                           : std::string()) +
                        ", found " + std::to_string(recordBytes));
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
    m_info.uniform = uniform;
    m_info.fileBytes = fileBytes;
    m_info.cube = CubeTransform{origin, edge};
    m_info.sourceOffset = sourceOffset;
    m_cloud =
        makeSortedCloud(m_info.cube, sourceOffset, attributes, static_cast<std::size_t>(pointCount),
                        storage, memoryBudgetBytes, tempDir);
    if (uniform.bits != 0) {
        m_cloud->setUniformColumns(uniform.intensityUniform() ? &uniform.intensity : nullptr,
                                   uniform.lasUniform() ? uniform.lasRecord.data() : nullptr);
    }
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
    // The cloud stores the file's uniform columns once (the constructor set them).
    assert(cloud.uniformIntensities() == m_info.uniform.intensityUniform() &&
           cloud.uniformLasColumn() == m_info.uniform.lasUniform());
    OmsRecordDecoder decoder(m_layout, m_info.attributes, m_info.path);
    oms::PayloadChecksum checksum;
    morton::Code previousCode = 0;

    m_stream.seek(oms::kHeaderBytes);
    for (std::size_t begin = 0; begin < count;) {
        if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) {
            summary.cancelled = true;
            return summary;
        }
        const std::size_t end = std::min(count, begin + rangePoints);
        m_block.resize((end - begin) * recordBytes);
        m_stream.readExact(m_block.data(), m_block.size(),
                           "records " + std::to_string(begin) + " to " + std::to_string(end - 1));
        checksum.update(m_block.data(), m_block.size());
        const SortedCloud::StagedRange out = cloud.stage(end);
        previousCode = decoder.decode(m_block.data(), end - begin, begin, previousCode, out);
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
                             hexText(m_expectedPayloadChecksum) + " for the record bytes " +
                             std::to_string(oms::kHeaderBytes) + "-" +
                             std::to_string(footerStart - 1) + ", they hash to " +
                             hexText(payloadChecksum) + ": the records are damaged");
    }
    cloud.markComplete();
    return summary;
}

} // namespace omicron
