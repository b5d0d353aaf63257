#include "io/ply/ply_writer.hpp"

#include "io/parallel_text_writer.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/common.hpp>

namespace omicron {

namespace {

// Points per write() call: bounded memory, few syscalls.
constexpr std::size_t kChunkPoints = 1 << 14;

const char* encodingName(PlyEncoding encoding) {
    switch (encoding) {
    case PlyEncoding::Ascii:
        return "ascii";
    case PlyEncoding::BinaryLittleEndian:
        return "binary_little_endian";
    case PlyEncoding::BinaryBigEndian:
        return "binary_big_endian";
    }
    return "binary_little_endian";
}

// A comment must stay on its header line.
std::string singleLine(std::string text) {
    std::replace_if(
        text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    return text;
}

std::string headerText(std::uint64_t pointCount, AttributeSet attributes,
                       const PlyWriteOptions& options) {
    std::string header = "ply\nformat ";
    header += encodingName(options.encoding);
    header += " 1.0\n";
    if (options.offset != glm::dvec3(0.0)) {
        // %.17g: the reader gets back exactly the double that was subtracted.
        char line[160];
        std::snprintf(line, sizeof line, "comment offset %.17g %.17g %.17g\n", options.offset.x,
                      options.offset.y, options.offset.z);
        header += line;
    }
    for (const std::string& comment : options.comments) {
        header += "comment " + singleLine(comment) + "\n";
    }
    header += "element vertex " + std::to_string(pointCount) + "\n";
    header += "property float x\nproperty float y\nproperty float z\n";
    if (attributes.has(Attribute::Normal)) {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if (attributes.has(Attribute::Color)) {
        header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    }
    if (attributes.has(Attribute::Intensity)) {
        header += "property ushort intensity\n";
    }
    header += "end_header\n";
    return header;
}

// Stored coordinates: float(source - offset), the subtraction done in double so that a
// georeferenced cloud keeps the precision the offset exists for.
glm::vec3 storedPosition(const glm::vec3& unit, const CubeTransform& cube,
                         const glm::dvec3& offset) {
    return glm::vec3(cube.toSource(unit) - offset);
}

class BinaryRecords {
public:
    explicit BinaryRecords(bool swapBytes) : m_swapBytes(swapBytes) {}

    template <typename T> void put(T value) {
        std::array<char, sizeof(T)> raw = std::bit_cast<std::array<char, sizeof(T)>>(value);
        if (m_swapBytes) {
            std::reverse(raw.begin(), raw.end());
        }
        m_bytes.insert(m_bytes.end(), raw.begin(), raw.end());
    }
    std::vector<char>& bytes() { return m_bytes; }

private:
    bool m_swapBytes;
    std::vector<char> m_bytes;
};

void writeBinaryBody(AtomicFileWriter& out, const PointBatch& points, const CubeTransform& cube,
                     const PlyWriteOptions& options) {
    const bool fileBigEndian = options.encoding == PlyEncoding::BinaryBigEndian;
    BinaryRecords records(fileBigEndian != (std::endian::native == std::endian::big));
    const bool normals = points.attributes.has(Attribute::Normal);
    const bool colors = points.attributes.has(Attribute::Color);
    const bool intensities = points.attributes.has(Attribute::Intensity);
    for (std::size_t start = 0; start < points.size(); start += kChunkPoints) {
        const std::size_t end = std::min(points.size(), start + kChunkPoints);
        records.bytes().clear();
        for (std::size_t i = start; i < end; ++i) {
            const glm::vec3 stored = storedPosition(points.positions[i], cube, options.offset);
            records.put(stored.x);
            records.put(stored.y);
            records.put(stored.z);
            if (normals) {
                records.put(points.normals[i].x);
                records.put(points.normals[i].y);
                records.put(points.normals[i].z);
            }
            if (colors) {
                records.put(points.colors[i].r);
                records.put(points.colors[i].g);
                records.put(points.colors[i].b);
            }
            if (intensities) {
                records.put(points.intensities[i]);
            }
        }
        out.write(records.bytes().data(), records.bytes().size());
    }
}

void appendFloat(std::string& line, float value) {
    char text[32];
    // Shortest text that parses back to the same float (to_chars guarantees the round trip).
    const auto result = std::to_chars(text, text + sizeof text, value);
    line.append(text, result.ptr);
}

void appendUnsigned(std::string& line, unsigned value) {
    char text[16];
    const auto result = std::to_chars(text, text + sizeof text, value);
    line.append(text, result.ptr);
}

// The ascii lines of points [begin, end), appended to `text`.
void appendAsciiLines(const PointBatch& points, const CubeTransform& cube,
                      const PlyWriteOptions& options, std::size_t begin, std::size_t end,
                      std::string& text) {
    const bool normals = points.attributes.has(Attribute::Normal);
    const bool colors = points.attributes.has(Attribute::Color);
    const bool intensities = points.attributes.has(Attribute::Intensity);
    for (std::size_t i = begin; i < end; ++i) {
        const glm::vec3 stored = storedPosition(points.positions[i], cube, options.offset);
        appendFloat(text, stored.x);
        text += ' ';
        appendFloat(text, stored.y);
        text += ' ';
        appendFloat(text, stored.z);
        if (normals) {
            for (int axis = 0; axis < 3; ++axis) {
                text += ' ';
                appendFloat(text, points.normals[i][axis]);
            }
        }
        if (colors) {
            for (int channel = 0; channel < 3; ++channel) {
                text += ' ';
                appendUnsigned(text, points.colors[i][channel]);
            }
        }
        if (intensities) {
            text += ' ';
            appendUnsigned(text, points.intensities[i]);
        }
        text += '\n';
    }
}

void writeAsciiBody(AtomicFileWriter& out, const PointBatch& points, const CubeTransform& cube,
                    const PlyWriteOptions& options) {
    writeTextInParallel(out, points.size(), kChunkPoints,
                        [&](std::size_t begin, std::size_t end, std::string& text) {
                            appendAsciiLines(points, cube, options, begin, end, text);
                        });
}

} // namespace

PlyStreamWriter::PlyStreamWriter(const std::string& path, std::uint64_t pointCount,
                                 AttributeSet attributes, const PlyWriteOptions& options)
    : m_out(path), m_options(options), m_attributes(attributes), m_pointCount(pointCount) {
    m_out.write(headerText(pointCount, attributes, options));
}

void PlyStreamWriter::append(const PointBatch& points, const CubeTransform& cube) {
    assert(points.consistent());
    if (points.attributes != m_attributes) {
        throw OutputError(m_out.targetPath() +
                          ": a batch's attributes differ from those the header declares");
    }
    if (points.size() > m_pointCount - m_pointsWritten) {
        throw OutputError(m_out.targetPath() + ": " +
                          std::to_string(m_pointsWritten + points.size()) +
                          " points appended, but the header declares " +
                          std::to_string(m_pointCount));
    }
    if (m_options.encoding == PlyEncoding::Ascii) {
        writeAsciiBody(m_out, points, cube, m_options);
    } else {
        writeBinaryBody(m_out, points, cube, m_options);
    }
    m_pointsWritten += points.size();
}

void PlyStreamWriter::finish() {
    if (m_pointsWritten != m_pointCount) {
        throw OutputError(m_out.targetPath() + ": only " + std::to_string(m_pointsWritten) +
                          " points appended, but the header declares " +
                          std::to_string(m_pointCount));
    }
    m_out.commit();
}

void writePly(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const PlyWriteOptions& options) {
    PlyStreamWriter writer(path, points.size(), points.attributes, options);
    writer.append(points, cube);
    writer.finish();
}

glm::dvec3 plyStorageOffset(const CubeTransform& cube, const glm::dvec3& preferred) {
    // float has a 24-bit mantissa: below 2^14 units, steps are finer than 0.001 units.
    constexpr double kPreciseRange = 16384.0;
    const glm::dvec3 low = cube.origin - preferred;
    const glm::dvec3 high = low + glm::dvec3(cube.edge);
    const double largest = std::max({std::abs(low.x), std::abs(low.y), std::abs(low.z),
                                     std::abs(high.x), std::abs(high.y), std::abs(high.z)});
    return largest <= kPreciseRange ? preferred : glm::floor(cube.origin);
}

} // namespace omicron
