#include "pipeline/build_pipeline.hpp"

#include "formats/omh_reader.hpp"
#include "formats/oms_reader.hpp"
#include "io/overlapped_batch_consumer.hpp"
#include "memory_budget.hpp"
#include "points/huge_page_buffer.hpp"
#include "points/huge_page_policy.hpp"
#include "scene/scene_generator.hpp"

#include <algorithm>
#include <chrono>
#include <future>
#include <stdexcept>

namespace omicron {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Copies points [begin, end) of `from` into `to` (same attributes), reusing its capacity.
void copySlice(const PointBatch& from, std::size_t begin, std::size_t end, PointBatch& to) {
    to.clear();
    to.attributes = from.attributes;
    to.appendRange(from, begin, end);
}

// The sorter's options for a run of pipeline 1 (a cloud file or the generated scene).
SortOptions sortOptionsOf(const PipelineOptions& options, const std::atomic<bool>& cancel) {
    SortOptions sortOptions;
    sortOptions.chunks = options.sortChunks;
    sortOptions.cancel = &cancel;
    sortOptions.storage = options.storage;
    sortOptions.memoryBudgetBytes = options.memoryBudgetBytes;
    sortOptions.tempDir = options.tempDir;
    if (!options.preview) {
        sortOptions.previewPoints = 0;
    }
    return sortOptions;
}

std::string describeCloud(const CloudInfo& info) {
    std::string text = info.formatDetail.empty() ? toString(info.format) : info.formatDetail;
    return text + ", " + std::to_string(info.pointCount) + " points";
}

} // namespace

const char* toString(BuildPhase phase) {
    switch (phase) {
    case BuildPhase::Idle:
        return "idle";
    case BuildPhase::Opening:
        return "opening";
    case BuildPhase::Reading:
        return "reading";
    case BuildPhase::Sorting:
        return "sorting";
    case BuildPhase::Building:
        return "building";
    case BuildPhase::Complete:
        return "complete";
    case BuildPhase::Cancelled:
        return "cancelled";
    case BuildPhase::Failed:
        return "failed";
    }
    return "unknown";
}

const char* toString(PipelineKind kind) {
    switch (kind) {
    case PipelineKind::UnsortedCloud:
        return "unsorted cloud -> incremental sorter -> builder";
    case PipelineKind::SortedStream:
        return "sorted stream (.oms) -> builder";
    case PipelineKind::GeneratedScene:
        return "generated scene -> incremental sorter -> builder";
    case PipelineKind::HierarchyFile:
        return "saved hierarchy (.omh) -> top-down load";
    }
    return "unknown";
}

// The pointers a failed run must give back; guarded by m_mutex when touched.
struct PipelineState {
    std::optional<PipelineSource> source;
    std::shared_ptr<const SortedCloud> cloud;
    std::shared_ptr<HierarchyBuilder> builder;
    std::shared_ptr<const Hierarchy> loaded;
    BuildStatistics loadedStatistics;
    BuildOptions loadedOptions;
};

PipelineResult BuildPipeline::run(const std::string& path, const PipelineOptions& options) {
    validate(options.build); // std::invalid_argument before anything is touched
    PipelineState saved;
    {
        std::lock_guard lock(m_mutex);
        saved = {m_source, m_cloud, m_builder, m_loaded, m_loadedStatistics, m_loadedOptions};
    }
    try {
        if (isOmhFile(path)) {
            return runHierarchyFile(path, options);
        }
        return isOmsFile(path) ? runSortedStream(path, options) : runCloud(path, options);
    } catch (...) {
        // A bad file changes nothing: the previous source, cloud and hierarchy stay shown.
        setPhase(BuildPhase::Failed);
        std::lock_guard lock(m_mutex);
        m_sorter.reset();
        m_source = std::move(saved.source);
        m_cloud = std::move(saved.cloud);
        m_builder = std::move(saved.builder);
        m_loaded = std::move(saved.loaded);
        m_loadedStatistics = std::move(saved.loadedStatistics);
        m_loadedOptions = saved.loadedOptions;
        m_pointsTotal.store(m_source ? m_source->pointCount : 0);
        throw;
    }
}

PipelineResult BuildPipeline::runHierarchyFile(const std::string& path,
                                               const PipelineOptions& options) {
    beginRun(BuildPhase::Opening);
    const auto start = Clock::now();
    OmhReader reader(path); // header, level table and footer checked: throws before any change
    const omh::Header& header = reader.header();
    // Points beyond the budget are paged in as the view asks for them; otherwise the whole
    // file loads top-down, as it always did.
    const std::uint64_t budget =
        options.memoryBudgetBytes > 0 ? options.memoryBudgetBytes : defaultMemoryBudget();
    if (reader.residentBytesOfAllPoints() > budget) {
        reader.pageOnDemand(budget);
    }
    PipelineSource source;
    source.path = path;
    source.kind = PipelineKind::HierarchyFile;
    source.description = "OMiCroN hierarchy (.omh), " + std::to_string(header.totalNodes) +
                         " nodes, " + std::to_string(header.totalPoints) + " point records";
    source.pointCount = header.totalPoints;
    source.attributes = header.attributes;
    source.cube = header.cube;
    source.sourceOffset = header.sourceOffset;

    BuildStatistics statistics;
    statistics.inputPoints = header.build.inputPoints;
    statistics.droppedPoints = header.build.droppedPoints;
    statistics.collapsedLeaves = header.build.collapsedLeaves;
    for (const omh::LevelEntry& level : header.levels) {
        statistics.levels.push_back({level.nodes, level.leaves, level.points});
    }
    m_sourceReads.fetch_add(1);
    {
        std::lock_guard lock(m_mutex);
        m_source = source;
        m_cloud.reset(); // a loaded file has no sorted cloud to rebuild or export from
        m_builder.reset();
        m_loaded = reader.hierarchy();
        m_loadedStatistics = statistics;
        m_loadedOptions.maxLevel = header.build.maxLevel;
        m_loadedOptions.ratio = header.build.ratio;
        m_loadedOptions.collapse = header.build.collapse;
        m_pointsTotal.store(source.pointCount);
    }
    setPhase(BuildPhase::Reading);
    std::uint64_t pointsLoaded = 0;
    reader.load(
        [&](int level) {
            pointsLoaded += header.levels[static_cast<std::size_t>(level)].points;
            m_pointsRead.store(pointsLoaded);
        },
        &m_cancel);
    PipelineResult result;
    result.source = source;
    result.pipeline = toString(PipelineKind::HierarchyFile);
    if (reader.pagedOnDemand()) {
        result.pipeline += ", points paged in on demand";
    }
    result.pagedPoints = reader.pagedOnDemand();
    result.readSeconds = secondsSince(start);
    result.cancelled = cancelled();
    statistics.complete = !result.cancelled;
    statistics.creationSeconds = result.readSeconds;
    {
        std::lock_guard lock(m_mutex);
        m_loadedStatistics = statistics;
    }
    result.stats = statistics;
    setPhase(result.cancelled ? BuildPhase::Cancelled : BuildPhase::Complete);
    return result;
}

void BuildPipeline::beginRun(BuildPhase phase) {
    m_pointsRead.store(0);
    m_bytesScanned.store(0);
    m_bytesToScan.store(0);
    m_sortRuns.store(0);
    {
        std::lock_guard lock(m_mutex);
        m_provisional.clear();
        m_hierarchyPreview.reset();
    }
    m_generation.fetch_add(1);
    setPhase(phase);
}

void BuildPipeline::setSource(const PipelineSource& source,
                              std::shared_ptr<const SortedCloud> cloud) {
    std::lock_guard lock(m_mutex);
    m_source = source;
    m_cloud = std::move(cloud);
    m_builder.reset();
    m_loaded.reset();
    m_pointsTotal.store(source.pointCount);
}

std::shared_ptr<HierarchyBuilder> BuildPipeline::startBuilder(const BuildOptions& options) {
    std::lock_guard lock(m_mutex);
    m_builder = std::make_shared<HierarchyBuilder>(m_cloud, options);
    return m_builder;
}

PipelineResult BuildPipeline::finishBuild(HierarchyBuilder& builder, PipelineResult result) {
    if (cancelled()) {
        builder.cancel();
    } else {
        setPhase(BuildPhase::Building);
    }
    builder.finish();
    builder.wait();
    result.stats = builder.statistics();
    result.cancelled = result.cancelled || cancelled() || !result.stats.complete;
    setPhase(result.cancelled ? BuildPhase::Cancelled : BuildPhase::Complete);
    return result;
}

PipelineResult BuildPipeline::sortIntoBuilder(IncrementalMortonSorter& sorter,
                                              HierarchyBuilder& builder, PipelineResult result) {
    if (!result.cancelled) {
        setPhase(BuildPhase::Sorting);
        const auto sortStart = Clock::now();
        sorter.sortAndEmit(builder.consumer());
        result.sortSeconds = secondsSince(sortStart);
        result.sortRuns = sorter.runCount();
        result.recycledBytes = std::uint64_t{sorter.pagesRecycled()} * kSmallPageBytes;
    }
    {
        // The sorter's unsorted copy of the input (or its runs) is as large as the cloud:
        // let it go.
        std::lock_guard lock(m_mutex);
        m_sorter.reset();
    }
    return finishBuild(builder, std::move(result));
}

PipelineResult BuildPipeline::runCloud(const std::string& path, const PipelineOptions& options) {
    beginRun(BuildPhase::Opening);
    OpenOptions openOptions;
    openOptions.cancel = &m_cancel;
    openOptions.onPrePassProgress = [&](std::uint64_t scanned, std::uint64_t fileBytes) {
        m_bytesToScan.store(fileBytes, std::memory_order_relaxed);
        m_bytesScanned.store(scanned, std::memory_order_relaxed);
        if (m_prePassObserver) {
            m_prePassObserver(scanned, fileBytes);
        }
    };
    openOptions.onPrePassPoints = [&](std::span<const glm::dvec3> sampled) {
        std::lock_guard lock(m_mutex);
        // The pre-pass samples about kPrePassSamplePoints; the cap only guards a bad estimate.
        const std::size_t room = 4 * kPrePassSamplePoints - m_provisional.size();
        m_provisional.insert(m_provisional.end(), sampled.begin(),
                             sampled.begin() + std::min(room, sampled.size()));
    };
    std::vector<glm::dvec3> hierarchyPositions;
    std::vector<glm::u8vec3> hierarchyColors;
    openOptions.onHierarchyPreview = [&](std::span<const glm::dvec3> positions,
                                         std::span<const glm::u8vec3> colors) {
        hierarchyPositions.assign(positions.begin(), positions.end());
        hierarchyColors.assign(colors.begin(), colors.end());
    };
    // The page-size probe (7 ms of first touches where the host takes freed pages back,
    // points/huge_page_policy) runs on another core while the file is opened; the sorter's
    // arrays wait for its answer.
    const auto pageSizeProbe = std::async(std::launch::async, [] { return hugePagesPayOff(); });
    std::unique_ptr<PointReader> reader;
    try {
        reader = openPointCloud(path, openOptions);
    } catch (const OpenCancelled&) {
        // Nothing was replaced yet: the previous source, cloud and hierarchy stay.
        setPhase(BuildPhase::Cancelled);
        PipelineResult result;
        result.pipeline = toString(PipelineKind::UnsortedCloud);
        result.source.path = path;
        result.cancelled = true;
        return result;
    }
    const CloudInfo& info = reader->info();
    const SortOptions sortOptions = sortOptionsOf(options, m_cancel);
    auto sorter = std::make_shared<IncrementalMortonSorter>(info, sortOptions);
    PipelineResult result;
    result.pipeline = toString(PipelineKind::UnsortedCloud);
    result.source = {path,
                     describeCloud(info),
                     PipelineKind::UnsortedCloud,
                     info.pointCount,
                     info.attributes,
                     info.cube,
                     info.sourceOffset};
    setSource(result.source, sorter->cloud());
    {
        std::lock_guard lock(m_mutex);
        m_sorter = sorter;
        m_provisional = {};
        if (!hierarchyPositions.empty()) {
            PreviewSample preview;
            preview.positions.reserve(hierarchyPositions.size());
            for (const glm::dvec3& p : hierarchyPositions) {
                preview.positions.push_back(info.cube.toUnit(p));
            }
            preview.colors = std::move(hierarchyColors);
            preview.pointsSeen = info.pointCount; // it stands for the whole cloud
            m_hierarchyPreview = std::move(preview);
        }
    }
    const auto builder = startBuilder(options.build);
    m_sourceReads.fetch_add(1);
    setPhase(BuildPhase::Reading);
    ReadOptions readOptions;
    readOptions.batchPoints = sortOptions.batchPoints;
    readOptions.cancel = &m_cancel;
    const auto readStart = Clock::now();
    // The sorter takes each batch on a thread of its own while the reader parses the next.
    OverlappedBatchConsumer sorterInput(
        [&](const PointBatch& batch, std::span<const morton::Code> codes) {
            sorter->add(batch, codes);
            m_pointsRead.fetch_add(batch.size(), std::memory_order_relaxed);
            m_sortRuns.store(sorter->runCount(), std::memory_order_relaxed);
        },
        [&](std::size_t pointsRead) {
            // The next batch's arrival pages, while the sorter still adds the last.
            return sorter->populateAhead(pointsRead + readOptions.batchPoints);
        });
    const ReadSummary read =
        reader->read([&](PointBatch& batch) { sorterInput.push(batch); }, readOptions);
    sorterInput.finish();
    result.readSeconds = secondsSince(readStart);
    result.skippedNonFinite = read.skippedNonFinite;
    result.cancelled = read.cancelled;
    return sortIntoBuilder(*sorter, *builder, std::move(result));
}

PipelineResult BuildPipeline::runSortedStream(const std::string& path,
                                              const PipelineOptions& options) {
    beginRun(BuildPhase::Opening);
    // A sorted stream larger than the budget streams into a file-backed cloud.
    OmsReader reader(path, options.storage,
                     options.memoryBudgetBytes > 0 ? options.memoryBudgetBytes
                                                   : defaultMemoryBudget(),
                     options.tempDir);
    const OmsInfo& info = reader.info();
    PipelineResult result;
    result.pipeline = toString(PipelineKind::SortedStream);
    result.source = {path,
                     "omicron sorted stream v" + std::to_string(info.version) + ", " +
                         std::to_string(info.pointCount) + " points",
                     PipelineKind::SortedStream,
                     info.pointCount,
                     info.attributes,
                     info.cube,
                     info.sourceOffset};
    setSource(result.source, reader.cloud());
    const auto builder = startBuilder(options.build);
    m_sourceReads.fetch_add(1);
    setPhase(BuildPhase::Sorting);
    ReadOptions readOptions;
    readOptions.cancel = &m_cancel;
    const auto readStart = Clock::now();
    const SortedRangeConsumer forward = builder->consumer();
    const ReadSummary read = reader.read(
        [&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
            m_pointsRead.store(end, std::memory_order_relaxed);
            forward(cloud, begin, end);
        },
        readOptions);
    result.readSeconds = secondsSince(readStart);
    result.cancelled = read.cancelled;
    return finishBuild(*builder, std::move(result));
}

PipelineResult BuildPipeline::runGeneratedScene(std::uint64_t points, std::uint64_t seed,
                                                const PipelineOptions& options) {
    validate(options.build);
    beginRun(BuildPhase::Opening);
    if (cancelled()) { // generation itself cannot stop part way: do not start it
        setPhase(BuildPhase::Cancelled);
        PipelineResult result;
        result.cancelled = true;
        return result;
    }
    const GeneratedScene scene = generateScene(points, seed);
    CloudInfo info;
    info.format = CloudFormat::Xyz; // unused for a sorter fed from memory
    info.formatDetail = "generated scene (seed " + std::to_string(seed) + ")";
    info.pointCount = scene.points.size();
    info.attributes = scene.points.attributes;
    info.sourceBounds = scene.sourceBounds;
    info.boundsFromHeader = true;
    info.cube = scene.cube;
    const SortOptions sortOptions = sortOptionsOf(options, m_cancel);
    auto sorter = std::make_shared<IncrementalMortonSorter>(info, sortOptions);
    PipelineResult result;
    result.pipeline = toString(PipelineKind::GeneratedScene);
    result.source = {"",
                     describeCloud(info),
                     PipelineKind::GeneratedScene,
                     info.pointCount,
                     info.attributes,
                     info.cube,
                     info.sourceOffset};
    setSource(result.source, sorter->cloud());
    {
        std::lock_guard lock(m_mutex);
        m_sorter = sorter;
    }
    const auto builder = startBuilder(options.build);
    m_sourceReads.fetch_add(1);
    setPhase(BuildPhase::Reading);
    const auto readStart = Clock::now();
    PointBatch batch;
    for (std::size_t begin = 0; begin < scene.points.size() && !cancelled();
         begin += sortOptions.batchPoints) {
        const std::size_t end = std::min(scene.points.size(), begin + sortOptions.batchPoints);
        copySlice(scene.points, begin, end, batch);
        sorter->add(batch);
        m_pointsRead.fetch_add(batch.size(), std::memory_order_relaxed);
        m_sortRuns.store(sorter->runCount(), std::memory_order_relaxed);
    }
    result.readSeconds = secondsSince(readStart);
    result.cancelled = cancelled();
    return sortIntoBuilder(*sorter, *builder, std::move(result));
}

PipelineResult BuildPipeline::rebuild(const BuildOptions& options) {
    validate(options);
    std::shared_ptr<const SortedCloud> cloud;
    PipelineResult result;
    {
        std::lock_guard lock(m_mutex);
        if (!m_cloud || !m_cloud->complete() || !m_source) {
            throw std::logic_error("rebuild needs a completely sorted cloud; none is kept");
        }
        cloud = m_cloud;
        result.source = *m_source;
    }
    beginRun(BuildPhase::Building);
    m_pointsRead.store(cloud->sortedEnd());
    result.pipeline = "kept sorted cloud -> builder (rebuild)";
    const auto builder = startBuilder(options);
    // One range for the whole cloud: the builder cuts it into worklists itself, and the
    // result does not depend on how the input was split into ranges.
    builder->onSortedRange(*cloud, 0, cloud->sortedEnd());
    return finishBuild(*builder, std::move(result));
}

void BuildPipeline::cancel() {
    m_cancel.store(true);
    std::shared_ptr<HierarchyBuilder> builder;
    {
        std::lock_guard lock(m_mutex);
        builder = m_builder;
    }
    if (builder) {
        builder->cancel();
    }
}

PipelineProgress BuildPipeline::progress() const {
    PipelineProgress progress;
    progress.phase = static_cast<BuildPhase>(m_phase.load());
    progress.generation = m_generation.load();
    progress.pointsTotal = m_pointsTotal.load();
    progress.pointsRead = m_pointsRead.load(std::memory_order_relaxed);
    progress.bytesToScan = m_bytesToScan.load(std::memory_order_relaxed);
    progress.bytesScanned = m_bytesScanned.load(std::memory_order_relaxed);
    progress.sortRuns = m_sortRuns.load(std::memory_order_relaxed);
    std::shared_ptr<HierarchyBuilder> builder;
    std::shared_ptr<const SortedCloud> cloud;
    {
        std::lock_guard lock(m_mutex);
        builder = m_builder;
        cloud = m_cloud;
    }
    if (cloud) {
        progress.pointsSorted = cloud->sortedEnd();
    }
    if (builder) {
        progress.pointsInserted = builder->statistics().inputPoints;
        progress.cutDelimiter = builder->hierarchy().publishedCut().delimiter;
        progress.maxLevel = builder->options().maxLevel;
    }
    return progress;
}

PreviewSample BuildPipeline::preview() const {
    std::shared_ptr<const IncrementalMortonSorter> sorter;
    PreviewSample provisional;
    {
        std::lock_guard lock(m_mutex);
        sorter = m_sorter;
        if (sorter && m_hierarchyPreview) {
            return *m_hierarchyPreview;
        }
        if (!sorter && !m_provisional.empty()) {
            // The bounds pre-pass's sample, framed by its own bounds so far: the final cube
            // is not known yet, and the sorter's preview replaces this one once reading starts.
            Bounds bounds;
            for (const glm::dvec3& p : m_provisional) {
                bounds.extend(p);
            }
            const CubeTransform frame = CubeTransform::fromBounds(bounds);
            provisional.positions.reserve(m_provisional.size());
            for (const glm::dvec3& p : m_provisional) {
                provisional.positions.push_back(frame.toUnit(p));
            }
            provisional.pointsSeen = m_provisional.size();
            provisional.provisional = true;
        }
    }
    return sorter ? sorter->preview() : provisional;
}

std::optional<PipelineSource> BuildPipeline::source() const {
    std::lock_guard lock(m_mutex);
    return m_source;
}

std::shared_ptr<const SortedCloud> BuildPipeline::sortedCloud() const {
    std::lock_guard lock(m_mutex);
    return m_cloud;
}

std::shared_ptr<const Hierarchy> BuildPipeline::hierarchy() const {
    std::lock_guard lock(m_mutex);
    return m_builder ? m_builder->sharedHierarchy() : m_loaded;
}

BuildStatistics BuildPipeline::statistics() const {
    std::shared_ptr<HierarchyBuilder> builder;
    {
        std::lock_guard lock(m_mutex);
        builder = m_builder;
    }
    if (builder) {
        return builder->statistics();
    }
    std::lock_guard lock(m_mutex);
    return m_loaded ? m_loadedStatistics : BuildStatistics{};
}

BuildOptions BuildPipeline::hierarchyOptions() const {
    std::lock_guard lock(m_mutex);
    return m_builder ? m_builder->options() : m_loadedOptions;
}

bool BuildPipeline::hasCompleteCloud() const {
    std::lock_guard lock(m_mutex);
    return m_cloud && m_cloud->complete();
}

} // namespace omicron
