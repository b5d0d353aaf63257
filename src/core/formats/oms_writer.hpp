// Writes a Morton-sorted cloud as a .oms sorted stream (layout in oms_format.hpp), atomically:
// the target is either the complete new file or left as it was.
#pragma once

#include "formats/oms_format.hpp"
#include "io/atomic_file_writer.hpp"
#include "points/cube_transform.hpp"
#include "points/sorted_cloud.hpp"

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>

namespace omicron {

// Streaming writer, so `omicron-cli sort` can write each range as the sorter emits it.
// Every error throws OutputError naming the file (I/O failures, and calls that would produce
// an invalid file: ranges out of order or out of Morton order, a point count that disagrees
// with open()). After a throw, or when destroyed before finish(), the temporary file is
// removed and the target is untouched.
class OmsWriter {
public:
    OmsWriter() = default;
    ~OmsWriter();
    OmsWriter(const OmsWriter&) = delete;
    OmsWriter& operator=(const OmsWriter&) = delete;

    // Starts the file and writes its header; `pointCount` (>= 1) is the exact number of
    // points the append() calls will deliver. The columns `uniform` holds are written once, in
    // the header (oms::uniformColumnsOf a cloud that keeps them so); every appended point must
    // then hold that value.
    void open(const std::string& path, const CubeTransform& cube, const glm::dvec3& sourceOffset,
              AttributeSet attributes, std::uint64_t pointCount,
              const oms::UniformColumns& uniform = {});

    // Appends [begin, end) of `cloud`, which must be published (end <= cloud.sortedEnd()) and
    // have the attributes given to open(). Ranges arrive in order: the first begins at 0 and
    // each begins where the previous ended. The Morton codes recomputed from the positions
    // (what a reader will see) must be non-decreasing across all ranges.
    void append(const SortedCloud& cloud, std::size_t begin, std::size_t end);

    // Appends the next points of a sorted stream (the attributes given to open()), as a sort
    // larger than memory emits them (IncrementalMortonSorter::emitSortedBatches); the same
    // order check as above.
    void append(const PointBatch& sorted);

    // Writes the footer and renames the temporary file onto the target.
    void finish();

    std::uint64_t pointsWritten() const { return m_pointsWritten; }

private:
    [[noreturn]] void fail(const std::string& what);
    // Point `index`'s record; a uniform column is checked against the header's value instead.
    void encodeRecord(std::uint64_t index, const glm::vec3& position, const glm::vec3* normal,
                      const glm::u8vec3* color, const std::uint16_t* intensity,
                      const std::uint8_t* las, std::uint8_t* record);

    std::string m_path;
    std::unique_ptr<AtomicFileWriter> m_file;
    std::unique_ptr<oms::PayloadChecksum> m_checksum;
    oms::RecordLayout m_layout; // without the uniform columns
    AttributeSet m_attributes;
    oms::UniformColumns m_uniform;
    std::uint64_t m_pointCount = 0;
    std::uint64_t m_pointsWritten = 0;
    morton::Code m_lastCode = 0;
    std::vector<std::uint8_t> m_block; // encoded records of the current append()
};

// Writes points [0, pointCount) of `cloud` (pointCount <= cloud.sortedEnd(), >= 1) as a .oms
// file, its uniform columns once. Throws OutputError.
void writeOms(const std::string& path, const SortedCloud& cloud, std::size_t pointCount);

} // namespace omicron
