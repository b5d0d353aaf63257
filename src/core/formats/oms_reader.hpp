// Streams a .oms sorted stream (layout in oms_format.hpp) straight into a SortedCloud: the
// paper's pipeline 2. Ranges reach the consumer with the same signature as the incremental
// sorter's (pipeline 1), so the hierarchy builder consumes both alike.
#pragma once

#include "formats/oms_format.hpp"
#include "io/file_stream.hpp"
#include "io/point_reader.hpp"
#include "points/sorted_cloud.hpp"
#include "sort/morton_sorter.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace omicron {

// What the header says, for `omicron-cli info`.
struct OmsInfo {
    std::string path;
    std::uint32_t version = 0;
    std::uint64_t pointCount = 0;
    int sortDepth = 0;
    AttributeSet attributes;
    std::size_t recordBytes = 0;
    oms::UniformColumns uniform; // the columns the header holds once (version 2)
    std::uint64_t fileBytes = 0;
    CubeTransform cube;           // unit cube -> source units
    glm::dvec3 sourceOffset{0.0}; // add to source units for the original coordinates
};

// True when `path` should be opened with OmsReader rather than openPointCloud(): its first 8
// bytes are the .oms magic, or its name ends in ".oms" (any case), so that a damaged .oms file
// gets this reader's precise error instead of "unknown format". Never throws.
bool isOmsFile(const std::string& path);

class OmsReader {
public:
    // Parses and validates the header and the footer's magic and count, checks the file size
    // against them, and allocates cloud() with capacity = point count. Throws InputError:
    // CannotOpen, NotARegularFile, EmptyFile, UnknownFormat (no magic), Truncated (the file is
    // shorter than header + count x record + footer), CountMismatch (longer, or the footer's
    // count differs), UnsupportedFeature (another version, sort depth, attribute bit, or a
    // big-endian file), MalformedHeader (header checksum, record size, non-finite cube, reserved
    // bytes, uniform columns the attributes lack), NoPoints (count 0). Version 1 files load as
    // they always did (no uniform columns).
    // `storage` is how cloud() keeps positions and colours. With a `memoryBudgetBytes`, an
    // exact cloud larger than half of it lives in an unnamed scratch file under `tempDir`
    // (empty: $TMPDIR or /tmp), kept out of memory beyond the budget (SortedCloud's
    // FileBacking); no room there is an OutputError naming the folder.
    explicit OmsReader(const std::string& path, PointStorage storage = PointStorage::Exact,
                       std::uint64_t memoryBudgetBytes = 0, const std::string& tempDir = {});

    const OmsInfo& info() const { return m_info; }
    std::shared_ptr<SortedCloud> cloud() const { return m_cloud; }

    // Streams the records into cloud() front to back, in ranges of at most options.batchPoints
    // points (and at most ~4 MiB of records): each range is decoded on every core, its codes
    // recomputed with morton::encodeUnit and checked for order (the first bad record in the
    // file is the one named), then published and handed to `consumer`, on the calling thread. After
    // the last range the payload checksum is verified and the cloud marked complete. Call at most
    // once. options.cancel is checked between ranges; a cancelled read returns with
    // summary.cancelled set and the cloud left incomplete. Throws InputError: Truncated (the file
    // shrank), MalformedValue (a non-finite position, a record out of Morton order, a payload
    // checksum mismatch). Ranges handed out before a checksum mismatch were decoded from a damaged
    // file: a caller must discard the cloud.
    ReadSummary read(const SortedRangeConsumer& consumer, const ReadOptions& options = {});

private:
    FileStream m_stream;
    OmsInfo m_info;
    oms::RecordLayout m_layout; // of the records: without the uniform columns
    std::uint64_t m_expectedPayloadChecksum = 0;
    std::shared_ptr<SortedCloud> m_cloud;
    std::vector<std::uint8_t> m_block;
    bool m_readCalled = false;
};

} // namespace omicron
