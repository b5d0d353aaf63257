// The incremental Morton sorter (the paper's pipeline 1): unsorted points in, a growing
// sorted prefix out, so rendering can start long before the whole cloud is sorted.
//
// While the input is read, add() computes each point's level-21 Morton code and drops
// (code, index) into one of 4096 bins by the code's top 12 bits: the counting pass and the
// first distribution are done as the data arrives. After the read the bins are grouped into K
// contiguous chunks of about equal point counts ("sort chunks"), and chunk after chunk is
// radix sorted (all cores) and copied into the SortedCloud, whose prefix is then published and
// handed to the consumer in batches — while the next chunk is already being sorted. The
// output is the stable Morton order of the input: identical for any K and thread count.
//
// A cloud whose in-memory sort would not fit the memory budget is sorted externally instead:
// add() buffers a run's worth of points and spills it sorted to the scratch folder
// (RunSpiller), and sortAndEmit() merges the runs (RunMerger) into the same stable order, so
// the output is point for point the same. The preview is taken while reading in both modes.
#pragma once

#include "io/point_reader.hpp"
#include "points/page_recycler.hpp"
#include "points/sorted_cloud.hpp"
#include "sort/bin_block_pool.hpp"
#include "sort/preview_sampler.hpp"
#include "sort/run_spiller.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace omicron {

// Measured with bench/sort_bench (see README): enough chunks that the first sorted batch
// arrives a small fraction of a full sort after reading ends, few enough that per-chunk
// overhead stays negligible.
inline constexpr int kDefaultSortChunks = 32;
inline constexpr int kMaxSortChunks = 256;

struct SortOptions {
    int chunks = kDefaultSortChunks;                  // 1..256
    std::size_t batchPoints = std::size_t{1} << 16;   // largest range handed to the consumer
    std::size_t previewPoints = std::size_t{1} << 16; // size of the random preview sample
    std::uint64_t previewSeed = 0x9e3779b97f4a7c15ull;
    const std::atomic<bool>* cancel = nullptr;        // checked between chunks and batches
    PointStorage storage = PointStorage::Exact;       // how the sorted cloud keeps its points
    // What the sort may keep resident (0: defaultMemoryBudget()); a cloud whose in-memory sort
    // needs more is sorted in runs on disk, under `tempDir` (empty: $TMPDIR or /tmp).
    std::uint64_t memoryBudgetBytes = 0;
    std::string tempDir = {};
    // An in-memory sort moves the input's pages into the sorted cloud as it gives them back
    // (points/page_recycler.hpp) rather than let the cloud fault in fresh ones (default: yes;
    // tests force either way), whole pages of `recyclePageBytes`: 0 for the cloud's own page
    // size (2 MiB where huge pages pay off, else 4 KiB), or a power of two from 4 KiB.
    std::optional<bool> recyclePages = std::nullopt;
    std::size_t recyclePageBytes = 0;
};

// Receives [begin, end) of `cloud`, already published: every code in it is >= every code of
// the ranges before. Called in order, on the thread that runs sortAndEmit().
using SortedRangeConsumer =
    std::function<void(const SortedCloud& cloud, std::size_t begin, std::size_t end)>;

// Receives the next points of the sorted stream (unit cube, the cloud's attributes); the
// batch is reused after the call.
using SortedBatchConsumer = std::function<void(const PointBatch& sorted)>;

class IncrementalMortonSorter {
public:
    // `info` of the reader that will feed add(); throws std::length_error beyond 2^32-1 points,
    // OutputError when a spilling sort cannot make its scratch folder or the file system there
    // lacks the space its runs need.
    IncrementalMortonSorter(const CloudInfo& info, const SortOptions& options);

    // Bytes the in-memory sort of `info`'s points keeps resident at its peak: the input in
    // arrival order, codes and indices in their bins, the sorted cloud, chunk scratch.
    static std::uint64_t inMemoryBytes(const CloudInfo& info);

    // True when this sort spills runs to disk (its in-memory sort exceeds the budget).
    bool spills() const { return m_spiller != nullptr; }
    // Runs written so far (0 for an in-memory sort).
    std::size_t runCount() const { return m_spiller ? m_spiller->runsWritten() : 0; }

    // Reading phase (one thread): appends a batch in the unit cube of info.cube.
    void add(const PointBatch& batch);
    // The same with the batch's level-21 codes already computed (morton::encodeUnit of each
    // position, one per point), as OverlappedBatchConsumer hands them over.
    void add(const PointBatch& batch, std::span<const morton::Code> codes);

    // One thread (not add()'s), while add() runs: faults in the arrival-order pages of the
    // next points whose pages no add() or earlier call has claimed, below `limit` points (a
    // step of them at a time). Returns false when there is nothing left to claim below
    // `limit`. The reader thread calls it while it waits for the sorter's thread
    // (OverlappedBatchConsumer), taking over part of the page faults that otherwise make the
    // sorter's side the longer.
    bool populateAhead(std::size_t limit);

    // Any thread, any time: a copy of the current preview sample (bounded size).
    PreviewSample preview() const;

    std::uint64_t pointCount() const { return m_pointsAdded; }
    std::shared_ptr<const SortedCloud> cloud() const { return m_cloud; }

    // Sorting phase: sorts chunk after chunk and calls `consumer` for every sorted range, in
    // Morton order. Returns the number of chunks used (<= options.chunks; 0 if cancelled
    // before the first; for a spilling sort, the number of runs merged). Call once, after the
    // last add().
    int sortAndEmit(const SortedRangeConsumer& consumer);

    // A spilling sort only, instead of sortAndEmit(): the merged stream in batches of at most
    // options.batchPoints, without filling the sorted cloud, so memory stays within the budget
    // whatever the cloud's size (how `omicron-cli sort` writes a .oms). Call once.
    void emitSortedBatches(const SortedBatchConsumer& consumer);

    // Pages of the input moved into the sorted cloud (PageRecycler) by sortAndEmit(), counted
    // in 4 KiB pages whatever the size moved.
    std::size_t pagesRecycled() const { return m_pagesRecycled; }

    // Seconds from the start of sortAndEmit() to the first consumer call (-1 before it).
    double firstRangeSeconds() const { return m_firstRangeSeconds; }

private:
    static constexpr int kBinBits = 12;
    static constexpr std::size_t kBins = std::size_t{1} << kBinBits;

    // A bin's input indices in arrival order, in blocks: a growing bin is never reallocated
    // and copied, and holds at most one partly filled block. Codes are not kept: the sort
    // computes them again from the positions, a bin at a time (8 bytes a point less).
    // The blocks come from m_binBlocks (sort/bin_block_pool.hpp), not the heap.
    static constexpr std::size_t kBinBlock = 4096;
    struct Bin {
        std::vector<std::uint32_t*> blocks;
        std::size_t count = 0;

        void push(std::uint32_t index, BinBlockPool& pool) {
            if (count % kBinBlock == 0) {
                blocks.push_back(static_cast<std::uint32_t*>(pool.allocate()));
            }
            blocks.back()[count % kBinBlock] = index;
            ++count;
        }
    };

    // The input is given back a block of points at a time, once every chunk that gathers from
    // the block has been sorted: blockLastBin is the highest bin of the block's points. (A
    // column recycled in huge pages goes back a whole page at a time: pagesDoneAfterChunk.)
    static constexpr int kReleaseBlockBits = 16;

    std::vector<std::size_t> chunkBinBoundaries() const;
    // Per input block, the chunk after which no later chunk gathers from it.
    std::vector<std::size_t> chunkDoneWithBlocks(const std::vector<std::size_t>& boundaries) const;
    // The same grouped: for each chunk, the blocks it is the last to gather from.
    static std::vector<std::vector<std::size_t>>
    blocksDoneAfterChunk(const std::vector<std::size_t>& blockChunks, std::size_t chunks);
    void releaseInputBlock(std::size_t block);
    // Gives back the blocks of bins [first, end) (sorted, not read again) and empties them.
    void releaseBins(std::size_t first, std::size_t end);
    // Backs the untouched pages of the range about to be gathered with given-back input.
    void prepareRecycledPages(const SortedCloud::StagedRange& out);
    int mergeAndEmit(const SortedRangeConsumer& consumer);
    bool cancelled() const;

    CloudInfo m_info;
    SortOptions m_options;
    std::shared_ptr<SortedCloud> m_cloud;

    // Input in arrival order (attributes are gathered from here into the sorted cloud).
    PointBatch m_input;
    // Per column, in this order: where the input's pages go when given back (null: back to
    // the kernel).
    enum Column : std::size_t { kPositions, kNormals, kColors, kIntensities, kLas, kColumns };
    std::array<std::unique_ptr<PageRecycler>, kColumns> m_recyclers;
    // The recyclers' page size: small pages go back block by block (releaseInputBlock), larger
    // ones a page at a time (pagesDoneAfterChunk).
    std::size_t m_recyclePageBytes = 0;
    bool recyclesByPage(std::size_t column) const {
        return m_recyclers[column] != nullptr && m_recyclePageBytes > kSmallPageBytes;
    }
    // For each chunk, per column that recycles its pages, the arrival array's whole pages (of
    // the recycler's size) none of whose points a later chunk gathers: a page larger than a
    // block is given back once the last of its blocks is done.
    using DonatedPages = std::array<std::vector<std::uintptr_t>, kColumns>;
    std::vector<DonatedPages> pagesDoneAfterChunk(const std::vector<std::size_t>& blockChunks,
                                                  std::size_t chunks) const;
    // What pagesDoneAfterChunk() donates of the arrival arrays, and what no whole page holds,
    // given back at the end (the head and tail pages of each array).
    void donateInputPages(const DonatedPages& pages);
    void releaseRecycledColumnsRest();
    // Per column, the arrival array's reserved memory and bytes per point (null: no column),
    // fixed once reserved: populateAhead() uses these, never the arrays themselves.
    struct ArrivalColumn {
        std::byte* base = nullptr;
        std::size_t pointBytes = 0;
    };
    std::array<ArrivalColumn, kColumns> m_arrivalColumns;
    // Per column, true while every point added so far has the first point's value (only ever
    // for the intensities and the LAS column): such a column's arrival array stays empty and
    // untouched (a spilling sort's runs leave it out), and the sorted cloud stores the value
    // once. Many LAS files hold zeros in most fields (converted or photogrammetric clouds: no GPS
    // time, intensity or returns). Atomic: populateAhead() reads them on another thread.
    std::array<std::atomic<bool>, kColumns> m_uniform{};
    std::uint16_t m_uniformIntensity = 0;
    std::vector<std::uint8_t> m_uniformLasRecord;
    // Keeps the uniform columns uniform while `batch` (the points from `firstIndex` on) agrees;
    // else (in memory) fills the column's arrival array up to `firstIndex` with its value, and
    // it is an ordinary column from then on.
    void checkUniformColumns(const PointBatch& batch, std::size_t firstIndex);
    // The columns uniform to the end go to the sorted cloud once, before its first range.
    void storeUniformColumns();
    // Appends `batch` to the arrival arrays, but for the uniform columns.
    void appendArrival(const PointBatch& batch);
    std::size_t m_arrivalCapacity = 0; // points the arrival arrays have room for
    // Points whose arrival pages are faulted in, or claimed by a thread doing it.
    std::atomic<std::size_t> m_populated{0};
    // While populateAhead() writes to pages: a point index at or below its step's first
    // (kNotTouching otherwise). Sequentially consistent with m_populated's claims, so add()
    // either sees the bound or made its claim before the step's.
    static constexpr std::size_t kNotTouching = SIZE_MAX;
    std::atomic<std::size_t> m_helperTouching{kNotTouching};
    // add()'s wait until no populateAhead() step below `end` is being written.
    void waitForHelper(std::size_t end) const;
    // Calls f(bytes, size) with the bytes of the points [begin, end) in each arrival array
    // that is stored (not uniform).
    template <typename F>
    void forEachArrivalRange(std::size_t begin, std::size_t end, F&& f) const {
        for (std::size_t c = 0; c < kColumns; ++c) {
            const ArrivalColumn& column = m_arrivalColumns[c];
            if (column.base != nullptr && column.pointBytes != 0 &&
                !m_uniform[c].load(std::memory_order_relaxed)) {
                f(column.base + begin * column.pointBytes, (end - begin) * column.pointBytes);
            }
        }
    }
    // Faults in the arrival pages of the points [begin, end) with one call per array.
    void populateArrival(std::size_t begin, std::size_t end) const;
    // The same from user space, only the pages wholly inside (touchWholePages).
    void touchArrival(std::size_t begin, std::size_t end) const;
    // Claims [m_populated, end) and faults its pages in (add()'s own batch).
    void populateUpTo(std::size_t end);
    std::size_t m_pagesRecycled = 0;
    BinBlockPool m_binBlocks{kBinBlock * sizeof(std::uint32_t), PageSize::Huge}; // outlives m_bins
    std::vector<Bin> m_bins;
    std::vector<std::uint16_t> m_blockLastBin;
    std::vector<morton::Code> m_batchCodes; // scratch for add()
    std::uint64_t m_pointsAdded = 0;
    std::unique_ptr<RunSpiller> m_spiller; // a spilling sort's runs, else null

    PreviewSampler m_preview;

    double m_firstRangeSeconds = -1.0;
};

struct SortSummary {
    ReadSummary read;
    std::uint64_t points = 0;
    int chunksUsed = 0;
    double readSeconds = 0.0;             // open excluded: streaming the points into the sorter
    double firstRangeAfterReadSeconds = -1.0;
    double sortAfterReadSeconds = 0.0;    // read end -> last range handed to the consumer
    std::size_t pagesRecycled = 0;        // see IncrementalMortonSorter::pagesRecycled()
    bool cancelled = false;
};

// Pipeline 1 in one call: reads every point of `reader` into a sorter and emits the sorted
// ranges. `onSorterReady`, when given, is called with the sorter as soon as it exists (before
// the read), so the caller can keep its cloud() and let another thread show its preview.
SortSummary sortPointCloud(PointReader& reader, const SortOptions& options,
                           const SortedRangeConsumer& consumer,
                           std::function<void(const IncrementalMortonSorter&)> onSorterReady = {});

} // namespace omicron
