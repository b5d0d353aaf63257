// Writes points as uncompressed LAS 1.2 or 1.4, atomically: a whole batch, or streamed.
#pragma once

#include "io/atomic_file_writer.hpp"
#include "points/bounds.hpp"
#include "points/cube_transform.hpp"
#include "points/point_batch.hpp"

#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <vector>

namespace omicron {

// A variable length record written between the header and the points.
struct LasVariableLengthRecord {
    std::string userId; // at most 16 characters
    std::uint16_t recordId = 0;
    std::string description;           // at most 32 characters
    std::vector<std::uint8_t> payload; // at most 65535 bytes
};

struct LasWriteOptions {
    std::uint8_t versionMinor = 2; // 2 (LAS 1.2: point formats 0 to 5) or 4 (LAS 1.4: 0 to 10)
    std::uint8_t pointFormat = 3;
    // Stored integers are round((source - offset) / scale); every one must fit in int32, so
    // georeferenced clouds need an offset near the data (e.g. CloudInfo::sourceOffset).
    glm::dvec3 scale{0.001}; // source units per step; finite and > 0
    glm::dvec3 offset{0.0};
    // Bytes after each record's standard fields: a cloud's LAS extra bytes (as many as fit),
    // zeros beyond them.
    std::uint16_t extraBytesPerRecord = 0;
    std::vector<LasVariableLengthRecord> vlrs;
};

// Variable length records stored as a LAS file stores them (a 54-byte header, then the
// payload; concatenated), as records to write. A truncated tail is left out.
std::vector<LasVariableLengthRecord> parseVariableLengthRecords(
    const std::vector<std::uint8_t>& stored);

// The LASF_Spec Extra Bytes record (id 4) describing `count` extra bytes per point as
// undocumented bytes (data type 0), so a LAS 1.4 reader knows their length.
LasVariableLengthRecord undocumentedExtraBytesRecord(std::uint16_t count);

// A LAS file written in pieces, so memory stays bounded whatever the count: the options are
// checked and the header (with the count) written when constructed, the records batch after
// batch, and finish() writes the header's bounds (those of the quantised coordinates) and
// commits, only when exactly `pointCount` points were appended. Destroyed without finish()
// (an error, a cancel), the target is untouched and the temporary removed. Fields as
// writeLas below. Throws OutputError.
class LasStreamWriter {
public:
    LasStreamWriter(const std::string& path, std::uint64_t pointCount, AttributeSet attributes,
                    const LasWriteOptions& options = {});
    // Appends every point of `points` (positions mapped to source units with `cube`); its
    // attributes must be the declared ones.
    void append(const PointBatch& points, const CubeTransform& cube);
    void finish();
    std::uint64_t pointsWritten() const { return m_pointsWritten; }

private:
    LasWriteOptions m_options;
    AttributeSet m_attributes;
    std::uint64_t m_pointCount;
    std::uint64_t m_pointsWritten = 0;
    Bounds m_steps; // of the stored integers
    std::vector<std::uint8_t> m_chunk;
    std::optional<AtomicFileWriter> m_file; // opened once the options are checked
};

// Writes every point of `points` (positions mapped back to source units with `cube`). The
// header's bounds are those of the quantised coordinates, so a reader's check against them is
// exact. Intensity and colour are written when the format has the field: 8-bit colour as
// value x 257 in the 16-bit fields (so 255 becomes 65535), an absent attribute as 0; an
// attribute the format lacks is dropped. Each point is a single first return, unclassified.
// Throws OutputError (bad options, a coordinate that does not fit in int32, an I/O error);
// the target is untouched on failure.
void writeLas(const std::string& path, const PointBatch& points, const CubeTransform& cube,
              const LasWriteOptions& options = {});

} // namespace omicron
