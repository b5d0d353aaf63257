// Writes points as PLY (ascii or binary, either endianness), atomically: a whole batch, or
// streamed.
#pragma once

#include "io/atomic_file_writer.hpp"
#include "points/cube_transform.hpp"
#include "points/point_batch.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace omicron {

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyWriteOptions {
    PlyEncoding encoding = PlyEncoding::BinaryLittleEndian;
    // Stored coordinates are float(source - offset); a non-zero offset is recorded as a
    // "comment offset X Y Z" line (the convention of ../shared/data), so georeferenced clouds
    // keep their precision.
    glm::dvec3 offset{0.0};
    std::vector<std::string> comments; // extra "comment" lines
};

// The offset to store float coordinates against: `preferred` (e.g. the source file's own
// offset) when float keeps millimetre steps relative to it, else the cube's origin rounded to
// whole units, so georeferenced clouds (LAS with coordinates of 10^6) keep their precision.
glm::dvec3 plyStorageOffset(const CubeTransform& cube, const glm::dvec3& preferred);

// A PLY file written in pieces: the header (which states the count) when constructed, then
// the points batch after batch, so memory stays bounded whatever the count. finish() commits
// only when exactly `pointCount` points were appended; destroyed without finish() (an error,
// a cancel), the target is untouched and the temporary file removed. Throws OutputError.
class PlyStreamWriter {
public:
    PlyStreamWriter(const std::string& path, std::uint64_t pointCount, AttributeSet attributes,
                    const PlyWriteOptions& options = {});
    // Appends every point of `points` (positions mapped to source units with `cube`, so one
    // cloud's copies can be written at other places); its attributes must be the declared ones.
    void append(const PointBatch& points, const CubeTransform& cube);
    void finish();
    std::uint64_t pointsWritten() const { return m_pointsWritten; }

private:
    AtomicFileWriter m_out;
    PlyWriteOptions m_options;
    AttributeSet m_attributes;
    std::uint64_t m_pointCount;
    std::uint64_t m_pointsWritten = 0;
};

// Writes every point of `points` (positions mapped back to source units with `cube`) with
// the attributes the batch has: float x y z, float nx ny nz, uchar red green blue, ushort
// intensity. Throws OutputError; the target is untouched on failure.
void writePly(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const PlyWriteOptions& options = {});

} // namespace omicron
