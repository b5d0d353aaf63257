#include "io/xyz/xyz_writer.hpp"

#include "io/parallel_text_writer.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

namespace omicron {

namespace {

constexpr int kNormalDecimals = 6;

// Decimals that keep a unit-cube float's resolution (edge * 2^-24) in source units, plus one.
int positionDecimals(double edge) {
    const double resolution = edge * 0x1.0p-24;
    return std::clamp(static_cast<int>(std::ceil(-std::log10(resolution))) + 1, 0, 17);
}

class LineBuilder {
public:
    void number(double value, int decimals) {
        separate();
        const auto result = std::to_chars(m_cursor, m_text.data() + m_text.size(), value,
                                          std::chars_format::fixed, decimals);
        m_cursor = result.ptr;
    }
    void integer(unsigned value) {
        separate();
        m_cursor = std::to_chars(m_cursor, m_text.data() + m_text.size(), value).ptr;
    }
    void finish(std::string& text) {
        *m_cursor++ = '\n';
        text.append(m_text.data(), static_cast<std::size_t>(m_cursor - m_text.data()));
        m_cursor = m_text.data();
    }

private:
    void separate() {
        if (m_cursor != m_text.data()) {
            *m_cursor++ = ' ';
        }
    }
    // Ten fixed-point numbers of at most 17 decimals and 309 integer digits fit easily.
    std::array<char, 4096> m_text{};
    char* m_cursor = m_text.data();
};

// What a point's line holds: intensity only without normals (the reader has no layout with
// both), positions with as many decimals as the cube's float resolution needs.
struct XyzColumns {
    bool normals;
    bool colors;
    bool intensities;
    int decimals;

    static XyzColumns of(const PointBatch& points, const CubeTransform& cube) {
        const bool normals = points.attributes.has(Attribute::Normal);
        return {normals, points.attributes.has(Attribute::Color),
                points.attributes.has(Attribute::Intensity) && !normals,
                positionDecimals(cube.edge)};
    }
};

// The lines of points [begin, end), appended to `text`.
void appendXyzLines(const PointBatch& points, const CubeTransform& cube, const glm::dvec3& offset,
                    const XyzColumns& columns, std::size_t begin, std::size_t end,
                    std::string& text) {
    LineBuilder line;
    for (std::size_t i = begin; i < end; ++i) {
        const glm::dvec3 source = cube.toSource(points.positions[i]) - offset;
        line.number(source.x, columns.decimals);
        line.number(source.y, columns.decimals);
        line.number(source.z, columns.decimals);
        if (columns.intensities) {
            line.integer(points.intensities[i]);
        }
        if (columns.colors) {
            for (int c = 0; c < 3; ++c) {
                line.integer(points.colors[i][c]);
            }
        }
        if (columns.normals) {
            for (int c = 0; c < 3; ++c) {
                line.number(points.normals[i][c], kNormalDecimals);
            }
        }
        line.finish(text);
    }
}

} // namespace

void writeXyz(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const glm::dvec3& offset) {
    const XyzColumns columns = XyzColumns::of(points, cube);
    AtomicFileWriter out(path);
    std::string header = "# x y z";
    header += columns.intensities ? " intensity" : "";
    header += columns.colors ? " r g b" : "";
    header += columns.normals ? " nx ny nz" : "";
    out.write(header + "\n");
    constexpr std::size_t kChunkPoints = 16384;
    writeTextInParallel(out, points.size(), kChunkPoints,
                        [&](std::size_t begin, std::size_t end, std::string& text) {
                            appendXyzLines(points, cube, offset, columns, begin, end, text);
                        });
    out.commit();
}

} // namespace omicron
