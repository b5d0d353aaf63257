#include "io/point_reader.hpp"

#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/las/las_reader.hpp"
#include "io/ply/ply_reader.hpp"
#include "io/xyz/xyz_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace omicron {

OpenCancelled::OpenCancelled(const std::string& path, std::uint64_t bytesScanned)
    : std::runtime_error(path + ": opening cancelled during the bounds pre-pass (after " +
                         std::to_string(bytesScanned) + " bytes)"),
      m_path(path), m_bytesScanned(bytesScanned) {}

const char* toString(CloudFormat format) {
    switch (format) {
    case CloudFormat::PlyAscii:
        return "PLY ascii";
    case CloudFormat::PlyBinaryLittleEndian:
        return "PLY binary little-endian";
    case CloudFormat::PlyBinaryBigEndian:
        return "PLY binary big-endian";
    case CloudFormat::Las:
        return "LAS";
    case CloudFormat::Laz:
        return "LAZ";
    case CloudFormat::Xyz:
        return "XYZ text";
    }
    return "unknown";
}

namespace {

std::string lowerExtension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

// The PLY format line decides between the three PLY variants.
CloudFormat plyVariant(const std::string& path, FileStream& stream) {
    std::array<char, 256> head{};
    stream.seek(0);
    const std::size_t got = stream.read(head.data(), head.size() - 1);
    const std::string_view text(head.data(), got);
    if (text.find("format binary_little_endian") != std::string_view::npos) {
        return CloudFormat::PlyBinaryLittleEndian;
    }
    if (text.find("format binary_big_endian") != std::string_view::npos) {
        return CloudFormat::PlyBinaryBigEndian;
    }
    if (text.find("format ascii") != std::string_view::npos) {
        return CloudFormat::PlyAscii;
    }
    throw InputError(InputErrorKind::MalformedHeader, path, InputLocation::byte(4),
                     "expected a 'format ascii|binary_little_endian|binary_big_endian 1.0' "
                     "line after 'ply'");
}

// LAZ writers mark the point format byte with bit 7 (or 6); the LAS reader also recognises a
// LAZ file by its 'laszip encoded' record when a writer left the byte plain.
CloudFormat lasVariant(FileStream& stream) {
    constexpr std::uint64_t kPointFormatByte = 104;
    std::uint8_t format = 0;
    stream.seek(kPointFormatByte);
    if (stream.read(&format, 1) == 1 && (format & 0xC0) != 0) {
        return CloudFormat::Laz;
    }
    return CloudFormat::Las;
}

std::string printableMagic(const char* bytes, std::size_t count) {
    std::string text;
    for (std::size_t i = 0; i < count; ++i) {
        const auto c = static_cast<unsigned char>(bytes[i]);
        if (c >= 0x20 && c < 0x7f) {
            text += static_cast<char>(c);
        } else {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
            text += escaped;
        }
    }
    return text;
}

} // namespace

CloudFormat detectFormat(const std::string& path) {
    FileStream stream(path);
    if (stream.size() == 0) {
        throw InputError(InputErrorKind::EmptyFile, path, InputLocation::none(),
                         "the file is empty (0 bytes), expected a point cloud");
    }
    std::array<char, 4> magic{};
    const std::size_t got = stream.read(magic.data(), magic.size());
    const std::string extension = lowerExtension(path);
    if (got >= 3 && std::memcmp(magic.data(), "ply", 3) == 0) {
        return plyVariant(path, stream);
    }
    if (got == 4 && std::memcmp(magic.data(), "LASF", 4) == 0) {
        return lasVariant(stream);
    }
    if (extension == ".laz") {
        throw InputError(InputErrorKind::UnknownFormat, path, InputLocation::byte(0),
                         "expected a LAZ file (compressed LAS, 'LASF' magic), found '" +
                             printableMagic(magic.data(), got) + "'");
    }
    if (extension == ".xyz" || extension == ".pts" || extension == ".txt" || extension == ".csv") {
        return CloudFormat::Xyz;
    }
    throw InputError(InputErrorKind::UnknownFormat, path, InputLocation::byte(0),
                     "unrecognised file: expected a PLY ('ply' magic), LAS or LAZ ('LASF' "
                     "magic) or XYZ text file (.xyz, .pts, .txt, .csv)");
}

std::unique_ptr<PointReader> openPointCloud(const std::string& path, const OpenOptions& options) {
    switch (detectFormat(path)) {
    case CloudFormat::PlyAscii:
    case CloudFormat::PlyBinaryLittleEndian:
    case CloudFormat::PlyBinaryBigEndian:
        return openPlyReader(path, options);
    case CloudFormat::Las:
    case CloudFormat::Laz:
        return openLasReader(path, options); // the header decides; both are LAS records
    case CloudFormat::Xyz:
        return openXyzReader(path, options);
    }
    throw InputError(InputErrorKind::UnknownFormat, path, InputLocation::none(),
                     "unrecognised format");
}

LoadedCloud loadPointCloud(const std::string& path, const OpenOptions& options) {
    LoadedCloud cloud;
    auto reader = openPointCloud(path, options);
    cloud.info = reader->info();
    cloud.points.attributes = cloud.info.attributes;
    cloud.points.reserve(static_cast<std::size_t>(cloud.info.pointCount));
    cloud.summary = reader->read([&](const PointBatch& batch) { cloud.points.append(batch); });
    return cloud;
}

} // namespace omicron
