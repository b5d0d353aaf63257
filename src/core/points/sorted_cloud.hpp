// A point cloud in Morton order that grows by its sorted prefix.
//
// Points keep their positions (unit cube), not their codes: a level-21 code is
// morton::encodeUnit(position), bit for bit what the sorter sorted by, so storing it would
// cost 8 bytes a point for nothing (a third of the cloud). Scans that only ask "same cell?"
// test positions against a UnitCellBox, which needs no bit interleaving.
//
// The arrays are allocated once, for the cloud's full capacity, and never move. A producer
// (the incremental sorter, or the .oms reader) fills them front to back and publishes the end
// of the finished prefix with a release store; any thread that loads sortedEnd() (acquire) may
// read [0, sortedEnd()) without locks: that part never changes again. This is the hand-off
// between the sorting stage and the hierarchy builder (pipelines 1 and 2 of the paper).
//
// A Morton-ordered cloud also keeps the code of every 64th point (block_codes.hpp), written by
// publish(): cutting the stream into leaves reads it instead of most positions.
//
// Positions and colours live in one of two stores (PointStorage): Exact keeps the floats and
// bytes as read; Packed quantises positions to the level-21 grid and bit-packs both
// (PackedPointStore: less than half the bytes, every point keeps its code). Read them through
// position(i) / color(i), or visitPositions() in hot loops; positions() / colors() expose the
// exact arrays only.
#pragma once

#include "points/block_codes.hpp"
#include "points/cube_transform.hpp"
#include "points/huge_page_buffer.hpp"
#include "points/morton.hpp"
#include "points/packed_points.hpp"
#include "points/point_batch.hpp"
#include "points/position_views.hpp"
#include "points/resident_set_governor.hpp"

#include <atomic>
#include <cassert>
#include <cstddef>
#include <glm/vec3.hpp>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace omicron {

// The order the points of a cloud are stored in.
enum class CloudOrder {
    Morton, // non-decreasing level-21 code: what the sorter and the .oms reader produce and the
            // builder needs (publish() asserts it at range boundaries)
    // The held points of a stored hierarchy's nodes, concatenated in node (breadth-first)
    // order, as the .omh reader loads them: a parent's sample repeats points of its leaves,
    // and codes restart at every level. Only a loaded Hierarchy indexes such a cloud.
    NodeOrder,
};

// How a cloud keeps its positions and colours.
enum class PointStorage {
    Exact,  // the floats and bytes as read (12 + 3 bytes a point)
    Packed, // level-21 cell centres and colours, bit-packed per 64 points (PackedPointStore)
};
const char* toString(PointStorage storage);
// "exact" or "packed"; false for anything else.
bool parsePointStorage(std::string_view text, PointStorage& out);

// A column of a cloud: point i's value is data[i * stride]. The stride is 0 for a uniform
// column (one value for every point, stored once); data is null when the cloud lacks it.
template <typename T> struct ColumnView {
    const T* data = nullptr;
    std::size_t stride = 0; // elements (bytes for the LAS column: a whole record)

    bool empty() const { return data == nullptr; }
    const T& operator[](std::size_t i) const { return data[i * stride]; }
};

class SortedCloud {
public:
    SortedCloud(const CubeTransform& cube, const glm::dvec3& sourceOffset, AttributeSet attributes,
                std::size_t capacity, CloudOrder order = CloudOrder::Morton,
                PointStorage storage = PointStorage::Exact, PageSize pages = PageSize::Huge);
    // A Morton-ordered exact cloud whose arrays live in an unnamed scratch file under
    // `backing.folder` (space reserved now; std::runtime_error naming the folder when it
    // cannot be), for a cloud larger than the memory budget: a thread drops the arrays' pages
    // from the resident set whenever the process exceeds `budgetBytes`
    // (points/resident_set_governor.hpp). Readers and the producer use it as any other cloud.
    SortedCloud(const CubeTransform& cube, const glm::dvec3& sourceOffset, AttributeSet attributes,
                std::size_t capacity, const FileBacking& backing, std::uint64_t budgetBytes);
    ~SortedCloud();

    SortedCloud(const SortedCloud&) = delete;
    SortedCloud& operator=(const SortedCloud&) = delete;

    const CubeTransform& cube() const { return m_cube; }
    const glm::dvec3& sourceOffset() const { return m_sourceOffset; }
    AttributeSet attributes() const { return m_attributes; }
    CloudOrder order() const { return m_order; }
    PointStorage storage() const { return m_packed ? PointStorage::Packed : PointStorage::Exact; }
    std::size_t capacity() const { return m_capacity; }

    // End of the finished prefix; everything before it is immutable.
    std::size_t sortedEnd() const { return m_sortedEnd.load(std::memory_order_acquire); }
    // True once the producer declared the cloud complete (sortedEnd() is then the point count).
    bool complete() const { return m_complete.load(std::memory_order_acquire); }

    // Read access; index only below a sortedEnd() value this thread has loaded.
    // The level-21 code of point `i` (computed from its position).
    morton::Code code(std::size_t i) const {
        const glm::vec3 p = position(i);
        return morton::encodeUnit(p.x, p.y, p.z);
    }
    glm::vec3 position(std::size_t i) const {
        return m_packed ? m_packed->position(i) : m_positions[i];
    }
    bool hasColors() const { return m_attributes.has(Attribute::Color); }
    glm::u8vec3 color(std::size_t i) const { return m_packed ? m_packed->color(i) : m_colors[i]; }
    // Calls f(ExactPositions) or f(PackedPositions): one loop, compiled for each store.
    template <typename F> decltype(auto) visitPositions(F&& f) const {
        if (m_packed) {
            return f(PackedPositions{m_packed.get()});
        }
        return f(ExactPositions{m_positions.data()});
    }
    // The block codes of points [0, end), end <= a loaded sortedEnd() (empty for NodeOrder).
    BlockCodes blockCodes(std::size_t end) const {
        return BlockCodes(m_blockCodes.data(), m_blockCodes.size() == 0 ? 0 : blockCodeCount(end));
    }
    // The exact store's arrays (empty for a packed cloud).
    std::span<const glm::vec3> positions() const { return m_positions; }
    std::span<const glm::u8vec3> colors() const { return m_colors; }
    // Either store keeps these as read.
    std::span<const glm::vec3> normals() const { return m_normals; }
    // Intensities, and the LAS column (points/las_fields.hpp, attributes().lasBytes() bytes a
    // point): empty without their attribute; uniform (stride 0) when every point shares the
    // first point's value, which is then stored once (setUniformColumns()).
    ColumnView<std::uint16_t> intensities() const {
        return {m_intensities.size() == 0 ? nullptr : m_intensities.data(), m_intensityStride};
    }
    ColumnView<std::uint8_t> lasColumn() const {
        return {m_las.size() == 0 ? nullptr : m_las.data(), m_lasStride};
    }
    const std::uint8_t* lasRecord(std::size_t i) const { return m_las.data() + i * m_lasStride; }
    // Producer side, before the first stage(): the intensities and/or the LAS column are the
    // same for every point, `intensity` and `lasRecord` (lasBytes() bytes): each is stored
    // once, and stage() hands out no span for it (a file-backed cloud keeps it in its file; a
    // paged one's pager leaves the value resident). The cloud must have the attribute.
    void setUniformColumns(const std::uint16_t* intensity, const std::uint8_t* lasRecord);
    bool uniformIntensities() const { return m_intensities.size() != 0 && m_intensityStride == 0; }
    bool uniformLasColumn() const { return m_las.size() != 0 && m_lasStride == 0; }
    // What the LAS column's extra bytes are (the source's Extra Bytes descriptors, 192 bytes
    // each), for a LAS export; empty when unknown. Set by the producer before it publishes.
    const std::vector<std::uint8_t>& lasExtraBytesDescriptors() const {
        return m_extraBytesDescriptors;
    }
    void setLasExtraBytesDescriptors(std::vector<std::uint8_t> descriptors) {
        m_extraBytesDescriptors = std::move(descriptors);
    }
    // The source's coordinate system as LAS variable length records (CloudInfo's), for a LAS
    // export; empty when unknown. Set by the producer before it publishes.
    const std::vector<std::uint8_t>& lasProjectionRecords() const { return m_projectionRecords; }
    void setLasProjectionRecords(std::vector<std::uint8_t> records) {
        m_projectionRecords = std::move(records);
    }

    // Producer side. The exact store is written in place, beyond sortedEnd(), then published:
    std::span<glm::vec3> mutablePositions() { return m_positions; }
    std::span<glm::vec3> mutableNormals() { return m_normals; }
    std::span<glm::u8vec3> mutableColors() { return m_colors; }
    std::span<std::uint16_t> mutableIntensities() { return m_intensities; }
    std::span<std::uint8_t> mutableLasColumn() { return m_las; }
    // ...or, for either store, the next points [sortedEnd(), end) are written through the spans
    // stage() returns (indexed from 0; an attribute the cloud lacks is empty) and published by
    // publish(end). For a packed cloud positions and colours go to a staging buffer that
    // publish() encodes; a file-backed cloud stages everything and publish() writes it to the
    // scratch files.
    struct StagedRange {
        std::span<glm::vec3> positions;
        std::span<glm::vec3> normals;
        std::span<glm::u8vec3> colors;
        std::span<std::uint16_t> intensities;
        std::span<std::uint8_t> las; // lasBytes() bytes a point
    };
    StagedRange stage(std::size_t end);

    // The whole arrays stage() hands out in place (in memory; positions and colours only in
    // the exact store), for a producer that backs their untouched pages itself
    // (points/page_recycler.hpp); empty spans for the others.
    struct InPlaceArrays {
        std::span<std::byte> positions;
        std::span<std::byte> normals;
        std::span<std::byte> colors;
        std::span<std::byte> intensities;
        std::span<std::byte> las;
    };
    InPlaceArrays inPlaceArrays();

    void publish(std::size_t newSortedEnd);
    void markComplete();

    // A cloud paged in on demand (PageSize::Small, exact store, NodeOrder): its arrays are
    // address space for every point, and a loader writes and releases ranges of them itself,
    // outside the sortedEnd() protocol (formats/omh_pager.hpp says who may read what, when).
    bool pagedOnDemand() const { return m_pages == PageSize::Small; }
    // Its arrays are in a scratch file, kept out of memory beyond the budget.
    bool fileBacked() const { return m_governor != nullptr; }
    // File-backed: points [begin, end) will be read soon (a writer's next batch): their pages
    // are read ahead into the page cache, without a fault each. No-op for other clouds.
    void willRead(std::size_t begin, std::size_t end) const;
    // File-backed: drops the arrays' pages now if the process is over the budget (the loops
    // that touch the most pages call it between batches; publish() does). No-op otherwise.
    void keepWithinBudget() const {
        if (m_governor) {
            m_governor->checkNow();
        }
    }
    // File-backed: the budget its governor keeps the process within (0 for other clouds).
    std::uint64_t residentBudget() const { return m_governor ? m_governor->limitBytes() : 0; }
    // File-backed: how often the arrays' pages were dropped to stay within the budget.
    std::uint64_t residentDrops() const;

    // Bytes of every array and store the cloud holds in memory (a paged cloud: the address
    // space; a file-backed one: only its block codes, the arrays are in the file).
    std::size_t bytesResident() const;

    // Copies [begin, end) into a batch (e.g. for a writer or a test).
    void copyRange(std::size_t begin, std::size_t end, PointBatch& out) const;

private:
    void writeStaged(std::size_t begin); // file-backed: the staged range to the files

    CubeTransform m_cube;
    glm::dvec3 m_sourceOffset;
    AttributeSet m_attributes;
    CloudOrder m_order;
    std::size_t m_capacity;
    PageSize m_pages;
    // On huge pages, uninitialised: the producer writes [0, capacity) before publishing.
    HugePageArray<glm::vec3> m_positions;
    HugePageArray<glm::vec3> m_normals;
    HugePageArray<glm::u8vec3> m_colors;
    HugePageArray<std::uint16_t> m_intensities;
    HugePageArray<std::uint8_t> m_las;
    // 1, or 0: uniform (only element 0 is stored) or no intensities.
    std::size_t m_intensityStride = m_attributes.has(Attribute::Intensity) ? 1 : 0;
    std::size_t m_lasStride = m_attributes.lasBytes(); // or 0: uniform (record 0 only)
    std::vector<std::uint8_t> m_extraBytesDescriptors;
    std::vector<std::uint8_t> m_projectionRecords;
    HugePageArray<morton::Code> m_blockCodes;   // CloudOrder::Morton only
    std::unique_ptr<PackedPointStore> m_packed; // Packed storage only
    // Packed or file-backed: the range stage() handed out, for publish() to encode or write.
    std::vector<glm::vec3> m_stagedPositions;
    std::vector<glm::vec3> m_stagedNormals; // file-backed only, as the three below
    std::vector<glm::u8vec3> m_stagedColors;
    std::vector<std::uint16_t> m_stagedIntensities;
    std::vector<std::uint8_t> m_stagedLas;
    std::atomic<std::size_t> m_sortedEnd{0};
    std::atomic<bool> m_complete{false};
    // File-backed only; last, so its thread stops before the arrays it drops go.
    std::unique_ptr<ResidentSetGovernor> m_governor;
};

} // namespace omicron
