#include "sort/morton_sorter.hpp"

#include "io/overlapped_batch_consumer.hpp"
#include "memory_budget.hpp"
#include "points/huge_page_buffer.hpp"
#include "points/huge_page_policy.hpp"
#include "points/morton_batch.hpp"
#include "sort/budgeted_cloud.hpp"
#include "sort/radix_sort.hpp"
#include "sort/run_merger.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <thread>

namespace omicron {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Runs are sized from half the budget; the rest covers the merge's read buffers, the write
// block and what the stages after the sort keep.
constexpr std::uint64_t kMinRunPoints = 4096;
// The sort's two gathers from the input in arrival order (positions for the keys, then every
// column into its sorted place) read at random over the whole input: each read is asked for
// this many points ahead (24.2 M LAS points: the sort 0.339 -> 0.301 s; 128 ahead no better).
constexpr std::size_t kGatherAhead = 64;

// Gathers the LAS column of points [begin, end) of a sorted range from their input places:
// `Bytes` known at compile time turns each copy into a few moves instead of a libc call per
// point (measured: the call was 9 % of a LAS build's CPU time).
template <std::size_t Bytes>
void gatherColumn(std::uint8_t* out, const std::uint8_t* in, const std::uint32_t* indices,
                  std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
        if (i + kGatherAhead < end) {
            __builtin_prefetch(in + std::size_t{indices[i + kGatherAhead]} * Bytes);
        }
        std::memcpy(out + i * Bytes, in + std::size_t{indices[i]} * Bytes, Bytes);
    }
}

void gatherColumn(std::uint8_t* out, const std::uint8_t* in, const std::uint32_t* indices,
                  std::size_t begin, std::size_t end, std::size_t bytes) {
    switch (bytes) { // the LAS column of formats 0/2, 1/3-7/9, 8/10 and with a few extra bytes
    case 8:
        return gatherColumn<8>(out, in, indices, begin, end);
    case 16:
        return gatherColumn<16>(out, in, indices, begin, end);
    case 18:
        return gatherColumn<18>(out, in, indices, begin, end);
    case 19:
        return gatherColumn<19>(out, in, indices, begin, end);
    case 20:
        return gatherColumn<20>(out, in, indices, begin, end);
    case 21:
        return gatherColumn<21>(out, in, indices, begin, end);
    case 24:
        return gatherColumn<24>(out, in, indices, begin, end);
    default:
        for (std::size_t i = begin; i < end; ++i) {
            std::memcpy(out + i * bytes, in + std::size_t{indices[i]} * bytes, bytes);
        }
    }
}

} // namespace

std::uint64_t IncrementalMortonSorter::inMemoryBytes(const CloudInfo& info) {
    // Input in arrival order + the sorted cloud's copy + bin index + code (in the sorted cloud
    // and as a key of the chunk being sorted) + chunk scratch.
    const std::uint64_t perPoint =
        2 * pointBytes(info.attributes) + sizeof(morton::Code) + sizeof(std::uint32_t) + 1;
    return info.pointCount * perPoint;
}

IncrementalMortonSorter::IncrementalMortonSorter(const CloudInfo& info, const SortOptions& options)
    : m_info(info), m_options(options), m_preview(options.previewPoints, options.previewSeed) {
    if (info.pointCount > UINT32_MAX) {
        throw std::length_error(info.path + ": " + std::to_string(info.pointCount) +
                                " points exceed the sorter's limit of 2^32-1");
    }
    m_options.chunks = std::clamp(m_options.chunks, 1, kMaxSortChunks);
    m_options.batchPoints = std::max<std::size_t>(m_options.batchPoints, 1);
    const std::uint64_t budget =
        m_options.memoryBudgetBytes != 0 ? m_options.memoryBudgetBytes : defaultMemoryBudget();
    m_options.memoryBudgetBytes = budget;
    const auto capacity = static_cast<std::size_t>(info.pointCount);
    const bool spills = inMemoryBytes(info) > budget;
    if (spills) {
        // First: it checks the scratch folder and its free space.
        const std::uint64_t runPoints = std::max(
            kMinRunPoints, budget / 2 / RunSpiller::bytesPerBufferedPoint(info.attributes));
        m_spiller = std::make_unique<RunSpiller>(
            m_options.tempDir, info.attributes,
            static_cast<std::size_t>(std::min<std::uint64_t>(runPoints, capacity)),
            info.pointCount);
    }
    // Even sorted, points beyond half the budget go to a scratch file (such a sort always
    // spills: its in-memory peak is over twice the cloud).
    m_cloud = makeSortedCloud(info.cube, info.sourceOffset, info.attributes, capacity,
                              m_options.storage, budget, m_options.tempDir);
    m_cloud->setLasExtraBytesDescriptors(info.lasExtraBytesDescriptors);
    m_cloud->setLasProjectionRecords(info.lasProjectionRecords);
    m_input.attributes = info.attributes;
    m_uniform[kIntensities] = info.attributes.has(Attribute::Intensity);
    m_uniform[kLas] = info.attributes.lasBytes() != 0;
    if (spills) {
        return;
    }
    m_bins.resize(kBins);
    m_blockLastBin.assign((capacity >> kReleaseBlockBits) + 1, 0);
    m_input.reserve(capacity);
    // The arrival-order arrays are the sort's largest first touch (~35 bytes a point): on
    // huge pages it costs a fault per 2 MiB instead of per 4 KiB.
    const auto advise = [](const auto& array) {
        adviseHugePages(array.data(), array.capacity() * sizeof(array[0]));
    };
    advise(m_input.positions);
    advise(m_input.normals);
    advise(m_input.colors);
    advise(m_input.intensities);
    advise(m_input.las);
    const auto column = [](auto& array, std::size_t pointBytes) {
        return ArrivalColumn{array.capacity() == 0 ? nullptr
                                                   : reinterpret_cast<std::byte*>(array.data()),
                             pointBytes};
    };
    m_arrivalCapacity = capacity;
    m_arrivalColumns = {column(m_input.positions, sizeof(glm::vec3)),
                        column(m_input.normals, sizeof(glm::vec3)),
                        column(m_input.colors, sizeof(m_input.colors[0])),
                        column(m_input.intensities, sizeof(m_input.intensities[0])),
                        column(m_input.las, m_input.attributes.lasBytes())};
    if (m_options.recyclePages.value_or(true)) {
        // On huge pages a page is moved whole, or the move would split it.
        m_recyclePageBytes = m_options.recyclePageBytes != 0 ? m_options.recyclePageBytes
                             : hugePagesPayOff()             ? kHugePageBytes
                                                             : kSmallPageBytes;
        const SortedCloud::InPlaceArrays sorted = m_cloud->inPlaceArrays();
        const std::array<std::span<std::byte>, kColumns> recipients{
            sorted.positions, sorted.normals, sorted.colors, sorted.intensities, sorted.las};
        for (std::size_t column = 0; column < recipients.size(); ++column) {
            if (!recipients[column].empty()) {
                m_recyclers[column] =
                    std::make_unique<PageRecycler>(recipients[column], m_recyclePageBytes);
            }
        }
    }
}

void IncrementalMortonSorter::add(const PointBatch& batch) {
    const std::size_t count = batch.size();
    m_batchCodes.resize(count);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 8192),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          morton::encodeUnitBatch(
                              std::span(batch.positions).subspan(range.begin(), range.size()),
                              std::span(m_batchCodes).subspan(range.begin(), range.size()));
                      });
    add(batch, m_batchCodes);
}

void IncrementalMortonSorter::add(const PointBatch& batch, std::span<const morton::Code> codes) {
    assert(codes.size() == batch.size());
    const std::size_t firstIndex = m_pointsAdded;
    if (firstIndex + batch.size() > m_cloud->capacity()) {
        throw std::length_error(m_info.path + ": the reader delivered more points than the " +
                                std::to_string(m_cloud->capacity()) + " its header declared");
    }
    const std::size_t count = batch.size();
    m_pointsAdded += count;
    m_preview.add(batch, firstIndex);
    if (m_spiller) {
        // A run leaves out the columns uniform so far; the merge puts their value back.
        checkUniformColumns(batch, firstIndex);
        m_spiller->add(batch, codes,
                       {m_uniform[kIntensities].load(std::memory_order_relaxed),
                        m_uniform[kLas].load(std::memory_order_relaxed)});
        return;
    }
    // The counting pass and first distribution, done while the data arrives.
    constexpr int binShift = 3 * morton::kMaxLevel - kBinBits;
    for (std::size_t i = 0; i < count; ++i) {
        const morton::Code code = codes[i];
        const auto binIndex = static_cast<std::uint16_t>((code >> binShift) & (kBins - 1));
        m_bins[binIndex].push(static_cast<std::uint32_t>(firstIndex + i), m_binBlocks);
        std::uint16_t& lastBin = m_blockLastBin[(firstIndex + i) >> kReleaseBlockBits];
        lastBin = std::max(lastBin, binIndex);
    }
    // The arrival arrays are reserved for the whole cloud and filled batch by batch: the
    // batch's new pages are faulted in by one call per array before the copy, unless
    // populateAhead() has claimed them already.
    checkUniformColumns(batch, firstIndex);
    populateUpTo(firstIndex + count);
    waitForHelper(firstIndex + count);
    appendArrival(batch);
}

void IncrementalMortonSorter::checkUniformColumns(const PointBatch& batch, std::size_t firstIndex) {
    if (batch.empty()) {
        return;
    }
    if (m_uniform[kIntensities].load(std::memory_order_relaxed)) {
        const auto& values = batch.intensities;
        if (firstIndex == 0) {
            m_uniformIntensity = values[0];
        }
        if (!std::all_of(values.begin(), values.end(),
                         [&](std::uint16_t v) { return v == m_uniformIntensity; })) {
            m_uniform[kIntensities].store(false, std::memory_order_relaxed);
            if (!m_spiller) {
                m_input.intensities.assign(firstIndex, m_uniformIntensity);
            }
        }
    }
    if (m_uniform[kLas].load(std::memory_order_relaxed)) {
        const std::size_t bytes = m_input.attributes.lasBytes();
        const auto& records = batch.las;
        if (firstIndex == 0) {
            m_uniformLasRecord.assign(records.begin(), records.begin() + bytes);
        }
        // Every record equals the first when the column repeats with a period of one record.
        const bool same =
            std::memcmp(records.data(), m_uniformLasRecord.data(), bytes) == 0 &&
            std::memcmp(records.data() + bytes, records.data(), records.size() - bytes) == 0;
        if (!same) {
            m_uniform[kLas].store(false, std::memory_order_relaxed);
            if (!m_spiller) {
                m_input.las.resize(firstIndex * bytes);
                for (std::size_t i = 0; i < firstIndex; ++i) {
                    std::memcpy(m_input.las.data() + i * bytes, m_uniformLasRecord.data(), bytes);
                }
            }
        }
    }
}

void IncrementalMortonSorter::appendArrival(const PointBatch& batch) {
    const auto append = [](auto& to, const auto& from) {
        to.insert(to.end(), from.begin(), from.end());
    };
    append(m_input.positions, batch.positions);
    append(m_input.normals, batch.normals);
    append(m_input.colors, batch.colors);
    if (!m_uniform[kIntensities].load(std::memory_order_relaxed)) {
        append(m_input.intensities, batch.intensities);
    }
    if (!m_uniform[kLas].load(std::memory_order_relaxed)) {
        append(m_input.las, batch.las);
    }
}

void IncrementalMortonSorter::populateArrival(std::size_t begin, std::size_t end) const {
    forEachArrivalRange(begin, end, populatePages);
}

void IncrementalMortonSorter::touchArrival(std::size_t begin, std::size_t end) const {
    forEachArrivalRange(begin, end, touchWholePages);
}

void IncrementalMortonSorter::populateUpTo(std::size_t end) {
    std::size_t from = m_populated.load();
    while (from < end && !m_populated.compare_exchange_weak(from, end)) {
    }
    if (from < end) {
        populateArrival(from, end);
    }
}

bool IncrementalMortonSorter::populateAhead(std::size_t limit) {
    // A step is about 0.5 MB of pages for a LAS cloud: short enough that the reader soon
    // sees the sorter take its batch.
    constexpr std::size_t kStepPoints = std::size_t{1} << 14;
    limit = std::min(limit, m_arrivalCapacity);
    std::size_t from = m_populated.load();
    // Announced before the claim, as a bound below it, so that add() never copies into a page
    // this thread may still be touching (see waitForHelper()).
    m_helperTouching.store(from);
    std::size_t to = 0;
    do {
        if (from >= limit) {
            m_helperTouching.store(kNotTouching, std::memory_order_release);
            return false;
        }
        to = std::min(limit, from + kStepPoints);
    } while (!m_populated.compare_exchange_weak(from, to));
    // Written from user space rather than populated with madvise: under a hypervisor that
    // shadows the guest's page tables, a page the kernel populated still costs an exit at its
    // first user access, and that fell to the sorter's copy. On such a 2-core VM, 512 MiB
    // populated from another thread, then copied: 0.06-0.27 s + 0.8-1.3 s; touched from another
    // thread, then copied: 1.6 s + 0.1-0.36 s. This thread is the reader, which would otherwise
    // wait.
    touchArrival(from, to);
    m_helperTouching.store(kNotTouching, std::memory_order_release);
    return true;
}

void IncrementalMortonSorter::waitForHelper(std::size_t end) const {
    // At most one step's touching (a fraction of a millisecond).
    while (m_helperTouching.load(std::memory_order_acquire) < end) {
        std::this_thread::yield();
    }
}

PreviewSample IncrementalMortonSorter::preview() const {
    return m_preview.sample();
}

bool IncrementalMortonSorter::cancelled() const {
    return m_options.cancel != nullptr && m_options.cancel->load(std::memory_order_relaxed);
}

// Bin index where each chunk starts, plus kBins at the end: contiguous bin ranges of about
// total/K points each (empty chunks are dropped, so all-identical points make one chunk).
std::vector<std::size_t> IncrementalMortonSorter::chunkBinBoundaries() const {
    const std::uint64_t total = m_input.size();
    std::vector<std::size_t> boundaries{0};
    std::uint64_t accumulated = 0;
    int chunk = 1;
    for (std::size_t bin = 0; bin < kBins && chunk < m_options.chunks; ++bin) {
        accumulated += m_bins[bin].count;
        const std::uint64_t target = total * static_cast<std::uint64_t>(chunk) /
                                     static_cast<std::uint64_t>(m_options.chunks);
        if (accumulated >= target && accumulated > 0 && accumulated < total) {
            boundaries.push_back(bin + 1);
            while (chunk < m_options.chunks &&
                   accumulated >= total * static_cast<std::uint64_t>(chunk) /
                                      static_cast<std::uint64_t>(m_options.chunks)) {
                ++chunk;
            }
        }
    }
    boundaries.push_back(kBins);
    return boundaries;
}

std::vector<std::size_t>
IncrementalMortonSorter::chunkDoneWithBlocks(const std::vector<std::size_t>& boundaries) const {
    const std::size_t blocks =
        (m_input.size() + (std::size_t{1} << kReleaseBlockBits) - 1) >> kReleaseBlockBits;
    std::vector<std::size_t> chunks(blocks);
    for (std::size_t block = 0; block < blocks; ++block) {
        // The chunk whose bins hold the block's last bin: the first boundary above it, minus 1.
        const auto next = std::upper_bound(boundaries.begin(), boundaries.end(),
                                           std::size_t{m_blockLastBin[block]});
        chunks[block] = static_cast<std::size_t>(next - boundaries.begin()) - 1;
    }
    return chunks;
}

std::vector<std::vector<std::size_t>>
IncrementalMortonSorter::blocksDoneAfterChunk(const std::vector<std::size_t>& blockChunks,
                                              std::size_t chunks) {
    std::vector<std::vector<std::size_t>> done(chunks);
    for (std::size_t block = 0; block < blockChunks.size(); ++block) {
        done[blockChunks[block]].push_back(block);
    }
    return done;
}

std::vector<IncrementalMortonSorter::DonatedPages>
IncrementalMortonSorter::pagesDoneAfterChunk(const std::vector<std::size_t>& blockChunks,
                                             std::size_t chunks) const {
    std::vector<DonatedPages> done(chunks);
    const std::size_t points = m_input.size();
    const std::size_t page = m_recyclePageBytes;
    for (std::size_t column = 0; column < kColumns; ++column) {
        const ArrivalColumn& arrival = m_arrivalColumns[column];
        if (!recyclesByPage(column) || arrival.base == nullptr || points == 0) {
            continue;
        }
        const auto base = reinterpret_cast<std::uintptr_t>(arrival.base);
        const std::size_t pointBytes = arrival.pointBytes;
        const WholePages pages = wholePages(arrival.base, points * pointBytes, page);
        for (std::uintptr_t first = pages.first; first < pages.last; first += page) {
            const std::size_t firstPoint = (first - base) / pointBytes;
            const std::size_t endPoint =
                std::min(points, (first + page - base + pointBytes - 1) / pointBytes);
            std::size_t chunk = 0;
            for (std::size_t block = firstPoint >> kReleaseBlockBits;
                 block <= (endPoint - 1) >> kReleaseBlockBits; ++block) {
                chunk = std::max(chunk, blockChunks[block]);
            }
            done[chunk][column].push_back(first);
        }
    }
    return done;
}

void IncrementalMortonSorter::donateInputPages(const DonatedPages& pages) {
    for (std::size_t column = 0; column < kColumns; ++column) {
        for (const std::uintptr_t page : pages[column]) {
            m_recyclers[column]->donate(reinterpret_cast<const void*>(page), m_recyclePageBytes);
        }
    }
}

void IncrementalMortonSorter::releaseRecycledColumnsRest() {
    for (std::size_t column = 0; column < kColumns; ++column) {
        const ArrivalColumn& arrival = m_arrivalColumns[column];
        if (recyclesByPage(column) && arrival.base != nullptr) {
            // The donated pages read as zero already; this frees the partial ones at the ends.
            releasePages(arrival.base, m_input.size() * arrival.pointBytes);
        }
    }
}

void IncrementalMortonSorter::releaseInputBlock(std::size_t block) {
    const std::size_t begin = block << kReleaseBlockBits;
    const std::size_t count =
        std::min(m_input.size(), begin + (std::size_t{1} << kReleaseBlockBits)) - begin;
    // Into the sorted cloud's next pages where a recycler takes them, else to the kernel.
    const auto release = [&](std::size_t column, const auto& array, std::size_t pointBytes) {
        if (array.empty() || recyclesByPage(column)) {
            return;
        }
        const auto* memory = reinterpret_cast<const std::uint8_t*>(array.data());
        if (m_recyclers[column]) {
            m_recyclers[column]->donate(memory + begin * pointBytes, count * pointBytes);
        } else {
            releasePages(memory + begin * pointBytes, count * pointBytes);
        }
    };
    release(kPositions, m_input.positions, sizeof(glm::vec3));
    release(kNormals, m_input.normals, sizeof(glm::vec3));
    release(kColors, m_input.colors, sizeof(glm::u8vec3));
    release(kIntensities, m_input.intensities, sizeof(std::uint16_t));
    release(kLas, m_input.las, m_input.attributes.lasBytes());
}

void IncrementalMortonSorter::releaseBins(std::size_t first, std::size_t end) {
    std::vector<void*> blocks;
    for (std::size_t bin = first; bin < end; ++bin) {
        blocks.insert(blocks.end(), m_bins[bin].blocks.begin(), m_bins[bin].blocks.end());
        m_bins[bin] = Bin{};
    }
    m_binBlocks.release(blocks);
}

void IncrementalMortonSorter::prepareRecycledPages(const SortedCloud::StagedRange& out) {
    const std::array<const void*, kColumns> ends{
        out.positions.data() + out.positions.size(), out.normals.data() + out.normals.size(),
        out.colors.data() + out.colors.size(), out.intensities.data() + out.intensities.size(),
        out.las.data() + out.las.size()};
    for (std::size_t column = 0; column < ends.size(); ++column) {
        if (m_recyclers[column]) {
            m_recyclers[column]->prepare(ends[column]);
        }
    }
}

int IncrementalMortonSorter::sortAndEmit(const SortedRangeConsumer& consumer) {
    if (m_spiller) {
        return mergeAndEmit(consumer);
    }
    const auto start = Clock::now();
    const std::vector<std::size_t> boundaries = chunkBinBoundaries();
    const std::size_t chunks = boundaries.size() - 1;
    // Input read in a spatially coherent order (scan lines, tiles) is given back as the sort
    // proceeds instead of at its end: the peak is then less than the input and the sorted
    // cloud side by side. Input in random order is only given back at the end.
    const std::vector<std::size_t> blockChunks = chunkDoneWithBlocks(boundaries);
    const std::vector<std::vector<std::size_t>> blocksDone =
        blocksDoneAfterChunk(blockChunks, chunks);

    // Chunk c covers sorted positions [chunkBegin[c], chunkBegin[c + 1]).
    std::vector<std::size_t> chunkBegin(chunks + 1, 0);
    std::size_t largestChunk = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
        std::size_t size = 0;
        for (std::size_t bin = boundaries[c]; bin < boundaries[c + 1]; ++bin) {
            size += m_bins[bin].count;
        }
        chunkBegin[c + 1] = chunkBegin[c] + size;
        largestChunk = std::max(largestChunk, size);
    }

    // A column uniform to the end is stored once, and not gathered.
    storeUniformColumns();
    if (m_cloud->uniformIntensities()) {
        m_recyclers[kIntensities].reset();
    }
    if (m_cloud->uniformLasColumn()) {
        m_recyclers[kLas].reset();
    }
    const std::vector<DonatedPages> pagesDone = pagesDoneAfterChunk(blockChunks, chunks);

    // Written before they are read: not zero-filled (a pass over 18 MB for 24.2 M points),
    // and on huge pages where they pay off: on small pages their 4,600 first touches took
    // about 55 ms of the sort on the test VM.
    HugePageArray<std::uint64_t> keys(largestChunk);
    HugePageArray<std::uint64_t> keyScratch(largestChunk);
    HugePageArray<std::uint32_t> indices(largestChunk);
    HugePageArray<std::uint32_t> indexScratch(largestChunk);
    SortedCloud& cloud = *m_cloud;

    std::size_t nextChunk = 0;
    int chunksDone = 0;
    // Stage 1 sorts a chunk (on all cores), stage 2 hands it out; two tokens let the consumer
    // work on chunk c while chunk c + 1 is sorted, and bound how far sorting runs ahead.
    tbb::parallel_pipeline(
        2, tbb::make_filter<void, std::size_t>(
               tbb::filter_mode::serial_in_order,
               [&](tbb::flow_control& control) -> std::size_t {
                   if (nextChunk == chunks || cancelled()) {
                       control.stop();
                       return 0;
                   }
                   const std::size_t c = nextChunk++;
                   const std::size_t size = chunkBegin[c + 1] - chunkBegin[c];
                   // Bins are the first radix digit (already distributed while reading), so
                   // each bin is sorted on its own, in parallel, in its final place.
                   std::vector<std::size_t> binOffset(boundaries[c + 1] - boundaries[c] + 1, 0);
                   for (std::size_t bin = boundaries[c]; bin < boundaries[c + 1]; ++bin) {
                       binOffset[bin - boundaries[c] + 1] =
                           binOffset[bin - boundaries[c]] + m_bins[bin].count;
                   }
                   tbb::parallel_for(boundaries[c], boundaries[c + 1], [&](std::size_t bin) {
                       Bin& from = m_bins[bin];
                       const std::size_t at = binOffset[bin - boundaries[c]];
                       const std::size_t n = from.count;
                       for (std::size_t b = 0; b < from.blocks.size(); ++b) {
                           const std::size_t first = b * kBinBlock;
                           std::copy_n(from.blocks[b], std::min(kBinBlock, n - first),
                                       indices.data() + at + first);
                       }
                       // The bin's positions, gathered a block at a time and coded on
                       // vector lanes: with the byte table point by point inside the gather,
                       // 24.2 M points sorted in 0.43 s instead of 0.38 s.
                       constexpr std::size_t kKeyBlock = 512;
                       std::array<glm::vec3, kKeyBlock> gathered;
                       for (std::size_t first = at; first < at + n; first += kKeyBlock) {
                           const std::size_t count = std::min(kKeyBlock, at + n - first);
                           for (std::size_t i = 0; i < count; ++i) {
                               if (first + i + kGatherAhead < at + n) {
                                   __builtin_prefetch(
                                       &m_input.positions[indices[first + i + kGatherAhead]]);
                               }
                               gathered[i] = m_input.positions[indices[first + i]];
                           }
                           morton::encodeUnitBatch(std::span(gathered.data(), count),
                                                   std::span(keys.data() + first, count));
                       }
                       radixSortByKey(std::span(keys.data() + at, n),
                                      std::span(indices.data() + at, n),
                                      std::span(keyScratch.data() + at, n),
                                      std::span(indexScratch.data() + at, n));
                   });
                   // Sorted bins are not read again: their blocks go back, a slab at a time
                   // as slabs empty, so what fills up meanwhile reuses the memory instead of
                   // raising the peak.
                   releaseBins(boundaries[c], boundaries[c + 1]);
                   // Gather every attribute into its sorted place.
                   const SortedCloud::StagedRange out = cloud.stage(chunkBegin[c + 1]);
                   prepareRecycledPages(out);
                   const std::size_t lasBytes = m_input.attributes.lasBytes();
                   tbb::parallel_for(tbb::blocked_range<std::size_t>(0, size, 8192),
                                     [&](const tbb::blocked_range<std::size_t>& range) {
                                         for (std::size_t i = range.begin(); i < range.end(); ++i) {
                                             // Written out here: the same prefetches in a
                                             // lambda made the sort 10 % slower (measured).
                                             if (i + kGatherAhead < range.end()) {
                                                 const std::uint32_t ahead =
                                                     indices[i + kGatherAhead];
                                                 __builtin_prefetch(&m_input.positions[ahead]);
                                                 if (!m_input.normals.empty()) {
                                                     __builtin_prefetch(&m_input.normals[ahead]);
                                                 }
                                                 if (!m_input.colors.empty()) {
                                                     __builtin_prefetch(&m_input.colors[ahead]);
                                                 }
                                                 if (!m_input.intensities.empty()) {
                                                     __builtin_prefetch(
                                                         &m_input.intensities[ahead]);
                                                 }
                                             }
                                             const std::uint32_t from = indices[i];
                                             out.positions[i] = m_input.positions[from];
                                             if (!m_input.normals.empty()) {
                                                 out.normals[i] = m_input.normals[from];
                                             }
                                             if (!m_input.colors.empty()) {
                                                 out.colors[i] = m_input.colors[from];
                                             }
                                             if (!m_input.intensities.empty()) {
                                                 out.intensities[i] = m_input.intensities[from];
                                             }
                                         }
                                         if (!m_input.las.empty()) {
                                             gatherColumn(out.las.data(), m_input.las.data(),
                                                          indices.data(), range.begin(),
                                                          range.end(), lasBytes);
                                         }
                                     });
                   for (const std::size_t block : blocksDone[c]) {
                       releaseInputBlock(block);
                   }
                   donateInputPages(pagesDone[c]);
                   cloud.publish(chunkBegin[c + 1]);
                   return c;
               }) &
               tbb::make_filter<std::size_t, void>(
                   tbb::filter_mode::serial_in_order, [&](std::size_t c) {
                       for (std::size_t begin = chunkBegin[c]; begin < chunkBegin[c + 1];) {
                           if (cancelled()) {
                               return;
                           }
                           const std::size_t end =
                               std::min(chunkBegin[c + 1], begin + m_options.batchPoints);
                           if (m_firstRangeSeconds < 0.0) {
                               m_firstRangeSeconds = secondsSince(start);
                           }
                           consumer(cloud, begin, end);
                           begin = end;
                       }
                       ++chunksDone;
                   }));
    releaseRecycledColumnsRest();
    for (std::unique_ptr<PageRecycler>& recycler : m_recyclers) {
        if (recycler) {
            m_pagesRecycled += recycler->pagesMoved();
            recycler.reset(); // gives back what the cloud did not need
        }
    }
    if (!cancelled() && static_cast<std::size_t>(chunksDone) == chunks) {
        cloud.markComplete();
    }
    return chunksDone;
}

void IncrementalMortonSorter::storeUniformColumns() {
    const bool uniformIntensities = m_pointsAdded != 0 && m_uniform[kIntensities].load();
    const bool uniformLas = m_pointsAdded != 0 && m_uniform[kLas].load();
    if (uniformIntensities || uniformLas) {
        m_cloud->setUniformColumns(uniformIntensities ? &m_uniformIntensity : nullptr,
                                   uniformLas ? m_uniformLasRecord.data() : nullptr);
    }
}

// The merge feeds the sorted cloud batch by batch: staged, published, handed out (but for
// the uniform columns emitSortedBatches() stored once).
int IncrementalMortonSorter::mergeAndEmit(const SortedRangeConsumer& consumer) {
    const auto start = Clock::now();
    SortedCloud& cloud = *m_cloud;
    std::size_t end = 0;
    emitSortedBatches([&](const PointBatch& sorted) {
        const std::size_t n = sorted.size();
        const SortedCloud::StagedRange out = cloud.stage(end + n);
        std::copy(sorted.positions.begin(), sorted.positions.end(), out.positions.begin());
        std::copy(sorted.normals.begin(), sorted.normals.end(), out.normals.begin());
        std::copy(sorted.colors.begin(), sorted.colors.end(), out.colors.begin());
        if (!out.intensities.empty()) {
            std::copy(sorted.intensities.begin(), sorted.intensities.end(),
                      out.intensities.begin());
        }
        if (!out.las.empty()) {
            std::copy(sorted.las.begin(), sorted.las.end(), out.las.begin());
        }
        cloud.publish(end + n);
        if (m_firstRangeSeconds < 0.0) {
            m_firstRangeSeconds = secondsSince(start);
        }
        consumer(cloud, end, end + n);
        end += n;
    });
    if (!cancelled() && end == m_pointsAdded) {
        cloud.markComplete();
    }
    return static_cast<int>(m_spiller->runs().size());
}

void IncrementalMortonSorter::emitSortedBatches(const SortedBatchConsumer& consumer) {
    if (!m_spiller) {
        throw std::logic_error("emitSortedBatches() needs a spilling sort");
    }
    m_spiller->finish();
    // The sorted cloud (filled by mergeAndEmit(), or only asked for its cube and uniform
    // columns by a writer) keeps them once.
    storeUniformColumns();
    // A quarter of the budget for the runs' read buffers, at least 64 KiB a run.
    const std::size_t runs = m_spiller->runs().size();
    const std::size_t bufferBytes = static_cast<std::size_t>(std::max<std::uint64_t>(
        m_options.memoryBudgetBytes / 4, std::uint64_t{runs} * (std::uint64_t{1} << 16)));
    // Runs spilled while a column was uniform left it out: the merge gives it the value.
    RunMerger merger(m_spiller->runs(), bufferBytes,
                     LeftOutColumns{m_uniformIntensity, m_uniformLasRecord.data()});
    PointBatch sorted;
    sorted.attributes = m_info.attributes;
    sorted.reserve(m_options.batchPoints);
    while (!cancelled()) {
        sorted.clear();
        if (merger.next(sorted, m_options.batchPoints) == 0) {
            break;
        }
        consumer(sorted);
    }
}

SortSummary sortPointCloud(PointReader& reader, const SortOptions& options,
                           const SortedRangeConsumer& consumer,
                           std::function<void(const IncrementalMortonSorter&)> onSorterReady) {
    SortSummary summary;
    IncrementalMortonSorter sorter(reader.info(), options);
    if (onSorterReady) {
        onSorterReady(sorter);
    }
    ReadOptions readOptions;
    readOptions.batchPoints = options.batchPoints;
    readOptions.cancel = options.cancel;
    const auto readStart = Clock::now();
    // The sorter takes each batch on a thread of its own while the reader parses the next.
    OverlappedBatchConsumer sorterInput(
        [&](const PointBatch& batch, std::span<const morton::Code> codes) {
            sorter.add(batch, codes);
        },
        [&](std::size_t pointsRead) {
            return sorter.populateAhead(pointsRead + readOptions.batchPoints);
        });
    summary.read = reader.read([&](PointBatch& batch) { sorterInput.push(batch); }, readOptions);
    sorterInput.finish();
    summary.readSeconds = secondsSince(readStart);
    summary.points = sorter.pointCount();
    if (summary.read.cancelled) {
        summary.cancelled = true;
        return summary;
    }
    const auto sortStart = Clock::now();
    summary.chunksUsed = sorter.sortAndEmit(consumer);
    summary.pagesRecycled = sorter.pagesRecycled();
    summary.sortAfterReadSeconds = secondsSince(sortStart);
    summary.firstRangeAfterReadSeconds = sorter.firstRangeSeconds();
    summary.cancelled = options.cancel != nullptr && options.cancel->load();
    return summary;
}

} // namespace omicron
