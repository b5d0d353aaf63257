// Streaming point-cloud readers: one interface for PLY, LAS, LAZ and XYZ text.
//
// Opening a file parses its header and, when the header has no bounding box (PLY, XYZ), runs a
// bounds pre-pass over the positions, so that every batch read() delivers is already in the
// unit cube of the final CubeTransform. Memory is bounded by the batch size, whatever the file
// size. Every failure is an InputError naming the file, the byte offset or line, and what was
// expected; a read either delivers every finite point of the file or throws.
#pragma once

#include "points/bounds.hpp"
#include "points/cube_transform.hpp"
#include "points/point_batch.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace omicron {

enum class CloudFormat { PlyAscii, PlyBinaryLittleEndian, PlyBinaryBigEndian, Las, Laz, Xyz };

const char* toString(CloudFormat format);

// What a reader knows about a cloud before streaming its points.
struct CloudInfo {
    std::string path;
    CloudFormat format = CloudFormat::Xyz;
    std::string formatDetail;     // e.g. "LAS 1.2, point format 3, 34-byte records"
    std::uint64_t pointCount = 0; // records in the file, non-finite ones included
    AttributeSet attributes;
    Bounds sourceBounds;          // source units, finite points only
    bool boundsFromHeader = false;  // false: from the pre-pass (or OpenOptions::knownBounds)
    glm::dvec3 sourceOffset{0.0};   // PLY "comment offset", LAS header offset
    CubeTransform cube;             // batch positions (unit cube) -> source units
    // LAS/LAZ: the Extra Bytes descriptors (io/las/las_extra_bytes.hpp) of the extra bytes in
    // the LAS column, when the file's describe exactly those bytes; empty otherwise.
    std::vector<std::uint8_t> lasExtraBytesDescriptors;
    // LAS/LAZ: the coordinate system's variable length records as the file stores them
    // (header and payload each, concatenated); empty when it has none.
    std::vector<std::uint8_t> lasProjectionRecords;
};

struct OpenOptions {
    // Skips the bounds pre-pass when the caller already knows the cloud's bounds in source
    // units (a second read of the same file). Points outside them make read() throw.
    std::optional<Bounds> knownBounds;
    // The bounds pre-pass (PLY, XYZ, LAS with unusable header bounds: a whole read of the
    // file before any point is delivered) checks this once per block of input (1 to 4 MiB)
    // and stops with OpenCancelled when it is set.
    const std::atomic<bool>* cancel = nullptr;
    // Called as the pre-pass advances (once per block, at its start and at its end) with the
    // bytes scanned and the file's size; it may set *cancel. One call at a time and in file
    // order, on the opening thread or, for a binary PLY (scanned on every core), on a oneTBB
    // worker of its arena.
    std::function<void(std::uint64_t bytesScanned, std::uint64_t fileBytes)> onPrePassProgress;
    // Called before each progress report (same thread as the report) with the source positions the
    // pre-pass sampled since the last one: an evenly strided sample of about kPrePassSamplePoints
    // finite points over the file, so a viewer can draw the cloud in a provisional frame
    // while its bounds are still being found (the first pixels of a large PLY or XYZ file).
    std::function<void(std::span<const glm::dvec3> sourcePositions)> onPrePassPoints;
    // Called once at opening, on the opening thread, for a cloud with a level of detail of its
    // own (COPC): the points of its top levels (about kPrePassSamplePoints), source positions
    // and colours (empty without colour), a uniform sample of the whole cloud that a viewer can
    // draw until the sorted points catch up.
    std::function<void(std::span<const glm::dvec3> sourcePositions,
                       std::span<const glm::u8vec3> colors)>
        onHierarchyPreview;
};

// About how many points the bounds pre-pass samples for OpenOptions::onPrePassPoints.
inline constexpr std::uint64_t kPrePassSamplePoints = std::uint64_t{1} << 16;

// What openPointCloud throws when OpenOptions::cancel stopped the bounds pre-pass: not an
// input error, the file may be fine.
class OpenCancelled : public std::runtime_error {
public:
    OpenCancelled(const std::string& path, std::uint64_t bytesScanned);
    const std::string& path() const { return m_path; }
    std::uint64_t bytesScanned() const { return m_bytesScanned; }

private:
    std::string m_path;
    std::uint64_t m_bytesScanned;
};

struct ReadOptions {
    std::size_t batchPoints = std::size_t{1} << 16;
    const std::atomic<bool>* cancel = nullptr; // checked between batches
};

struct ReadSummary {
    std::uint64_t pointsDelivered = 0;
    std::uint64_t skippedNonFinite = 0; // NaN/Inf coordinates: skipped, never delivered
    std::uint64_t batches = 0;
    bool cancelled = false;
};

// Receives each batch; the batch is reused after the call returns. A consumer may take the
// batch's columns by swapping it with a batch of the same attributes and column sizes
// (OverlappedBatchConsumer hands batches to its thread so, without copying them): a reader
// relies on neither a delivered batch's contents nor its capacity, only on its sizes.
using BatchConsumer = std::function<void(PointBatch&)>;

class PointReader {
public:
    virtual ~PointReader() = default;
    PointReader(const PointReader&) = delete;
    PointReader& operator=(const PointReader&) = delete;

    const CloudInfo& info() const { return m_info; }

    // Streams every point once, in file order. Call at most once per reader.
    virtual ReadSummary read(const BatchConsumer& consumer, const ReadOptions& options = {}) = 0;

protected:
    PointReader() = default;
    CloudInfo m_info;
};

// Identifies the format by magic bytes ("ply", "LASF": LAZ when the point format byte has a
// compression bit), then by extension (.xyz .pts .txt .csv); throws InputError for
// missing/unreadable files, directories, empty files and anything else unrecognised.
CloudFormat detectFormat(const std::string& path);

// Opens any supported cloud (header parsed, bounds known); throws InputError, or
// OpenCancelled when options.cancel stops the bounds pre-pass.
std::unique_ptr<PointReader> openPointCloud(const std::string& path, const OpenOptions& = {});

// Convenience for tests and small files: reads the whole cloud into one batch.
struct LoadedCloud {
    CloudInfo info;
    PointBatch points;
    ReadSummary summary;
};
LoadedCloud loadPointCloud(const std::string& path, const OpenOptions& = {});

} // namespace omicron
