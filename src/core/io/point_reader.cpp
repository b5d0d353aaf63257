#include "io/point_reader.hpp"

#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/las/las_reader.hpp"
#include "io/ply/ply_reader.hpp"
#include "io/xyz/xyz_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
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
        return CloudFormat::Las; // LAZ shares the signature; the LAS reader rejects it
    }
    if (extension == ".laz") {
        throw InputError(InputErrorKind::UnsupportedFeature, path, InputLocation::none(),
                         "LAZ (compressed LAS) is not supported; decompress it first, e.g. "
                         "'laszip -i FILE.laz -o FILE.las' or 'pdal translate FILE.laz FILE.las'");
    }
    if (extension == ".xyz" || extension == ".pts" || extension == ".txt" || extension == ".csv") {
        return CloudFormat::Xyz;
    }
    throw InputError(InputErrorKind::UnknownFormat, path, InputLocation::byte(0),
                     "unrecognised file: expected a PLY ('ply' magic), LAS ('LASF' magic) or "
                     "XYZ text file (.xyz, .pts, .txt, .csv)");
}

std::unique_ptr<PointReader> openPointCloud(const std::string& path, const OpenOptions& options) {
    switch (detectFormat(path)) {
    case CloudFormat::PlyAscii:
    case CloudFormat::PlyBinaryLittleEndian:
    case CloudFormat::PlyBinaryBigEndian:
        return openPlyReader(path, options);
    case CloudFormat::Las:
        return openLasReader(path, options);
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
