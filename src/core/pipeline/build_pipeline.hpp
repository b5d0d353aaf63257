// The whole build as one object: source (a cloud file, a .oms sorted stream or the generated
// default scene) -> incremental Morton sorter -> HierarchyBuilder, on the calling thread, with
// progress any other thread can poll. Front ends (the CLI's build and render commands, the
// desktop application's builder service) drive the same code.
//
// Threads. run*() and rebuild() block the thread that calls them (the builder's own master
// thread and oneTBB do the parallel work); every other member may be called from any thread
// at any time: progress() reads atomics, the rest copy shared pointers under a mutex. A GUI
// therefore runs the pipeline on a worker thread and polls progress() from a timer.
//
// Flexibility (the paper's argument for sorting once): the complete SortedCloud is kept after
// a build, and rebuild() feeds it to a new HierarchyBuilder with other depth, ratio, leaf
// collapse or worklist size, without reading or sorting again.
#pragma once

#include "build/build_options.hpp"
#include "build/build_statistics.hpp"
#include "build/hierarchy.hpp"
#include "build/hierarchy_builder.hpp"
#include "io/point_reader.hpp"
#include "points/sorted_cloud.hpp"
#include "sort/morton_sorter.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace omicron {

// Where the pipeline stands; ordered as a build advances.
enum class BuildPhase : int {
    Idle,      // nothing run yet
    Opening,   // parsing the header (and the bounds pre-pass), or generating the scene
    Reading,   // streaming points into the sorter (pipeline 1)
    Sorting,   // emitting sorted chunks (pipeline 1) or streaming a .oms file (pipeline 2)
    Building,  // all input handed to the builder; the hierarchy is being completed
    Complete,  // the hierarchy is complete
    Cancelled, // cancel() stopped the run; the cut built so far stays valid
    Failed,    // the run threw (the exception went to the caller)
};

const char* toString(BuildPhase phase);

// Which of the paper's pipelines a source runs.
enum class PipelineKind {
    UnsortedCloud,  // pipeline 1: PLY/LAS/XYZ -> incremental sorter -> builder
    SortedStream,   // pipeline 2: .oms -> builder
    GeneratedScene, // pipeline 1 fed from memory: the built-in default cloud
    HierarchyFile,  // pipeline 3: a saved .omh hierarchy, loaded top-down level by level
};

const char* toString(PipelineKind kind);

// A consistent-enough snapshot for a progress bar: each counter only grows during a run.
struct PipelineProgress {
    BuildPhase phase = BuildPhase::Idle;
    std::uint64_t pointsTotal = 0;    // points the source announces (0 before it is opened)
    std::uint64_t pointsRead = 0;     // read into the sorter (== sorted for a .oms file)
    std::uint64_t pointsSorted = 0;   // published sorted prefix
    std::uint64_t pointsInserted = 0; // concatenated into the cut (after the last fix pass)
    morton::Code cutDelimiter = 0;    // m_C of the last complete fix pass; 0 before it
    int maxLevel = 0;                 // depth of the current build (for cutDelimiter)
    std::uint64_t generation = 0;     // bumped by every run*() and rebuild()
    // The bounds pre-pass of a PLY or XYZ file (phase Opening): bytes scanned of the file's
    // size; both 0 when the source has no pre-pass (LAS, .oms, .omh, the generated scene).
    std::uint64_t bytesScanned = 0;
    std::uint64_t bytesToScan = 0;

    // Pipeline 1 beyond the memory budget: sorted runs spilled to disk so far (read phase),
    // then merged (sorting phase); 0 when the sort fits in memory.
    std::uint64_t sortRuns = 0;

    // Opening a file that is being scanned for its bounds: no point is read yet.
    bool scanningBounds() const { return phase == BuildPhase::Opening && bytesToScan > 0; }
};

// What the source is, known once it is opened.
struct PipelineSource {
    std::string path;        // empty for the generated scene
    std::string description; // e.g. "PLY binary little endian, 35947 points"
    PipelineKind kind = PipelineKind::UnsortedCloud;
    std::uint64_t pointCount = 0;
    AttributeSet attributes;
    CubeTransform cube; // unit cube -> source units
    glm::dvec3 sourceOffset{0.0};
};

// What a run did; the statistics are the builder's final snapshot.
struct PipelineResult {
    PipelineSource source;
    BuildStatistics stats;
    double readSeconds = 0.0; // streaming the points (and, for .oms, the sorted ranges)
    double sortSeconds = 0.0; // sorter emission after the read; 0 for .oms and rebuild
    std::size_t sortRuns = 0; // runs spilled to disk and merged (0: sorted in memory)
    // Bytes of the input's pages moved into the sorted cloud rather than faulted in anew
    // (IncrementalMortonSorter::pagesRecycled).
    std::uint64_t recycledBytes = 0;
    // A .omh larger than the memory budget: its nodes were loaded, their points are paged in
    // as a front asks for them (hierarchy()->residency()).
    bool pagedPoints = false;
    std::uint64_t skippedNonFinite = 0;
    bool cancelled = false;
    std::string pipeline; // human-readable, e.g. "unsorted cloud -> incremental sorter -> builder"
};

struct PipelineOptions {
    BuildOptions build;
    int sortChunks = kDefaultSortChunks; // 1..kMaxSortChunks, pipeline 1 only
    // How the sorted cloud keeps positions and colours (pipelines 1 and 2; a rebuild keeps the
    // cloud it has).
    PointStorage storage = PointStorage::Exact;
    // What the sort may keep resident (0: defaultMemoryBudget()); beyond it, pipeline 1 sorts
    // in runs on disk under `tempDir` (empty: $TMPDIR or /tmp) and merges them into the cloud.
    // The sorted cloud itself stays resident for the builder (15 bytes a point exact, about 7
    // packed). A .omh whose points exceed it opens with its points paged in on demand, the
    // least recently used evicted to stay within it (formats/omh_pager.hpp).
    std::uint64_t memoryBudgetBytes = 0;
    std::string tempDir = {};
    // The random sample of the points read so far that a viewer draws before the first
    // sorted batch (preview()). Front ends that show nothing while reading turn it off: the
    // sample costs the sorter's thread, which bounds the read phase, a few draws per point it
    // takes (12 ms of autzen_south's 72 ms read phase).
    bool preview = true;
};

// Points and seed of the built-in default scene when a front end shows it at start-up.
inline constexpr std::uint64_t kDefaultScenePoints = 2'000'000;
inline constexpr std::uint64_t kDefaultSceneSeed = 1;

class BuildPipeline {
public:
    BuildPipeline() = default;
    BuildPipeline(const BuildPipeline&) = delete;
    BuildPipeline& operator=(const BuildPipeline&) = delete;
    // Cancels a build still running on another thread is the owner's job (cancel(), then join
    // that thread); the destructor only releases what this object holds.
    ~BuildPipeline() = default;

    // Pipeline 1, 2 or 3 for `path` (.oms and .omh by magic or extension, see isOmsFile and
    // isOmhFile). A .omh file is loaded, not built: its hierarchy is complete from the start
    // and fills top-down; no sorted cloud is kept (rebuild() then needs the cloud again). Throws
    // InputError for a bad file and std::invalid_argument for bad options (before any read);
    // the previous cloud and hierarchy are kept on a throw. A cancelled run returns with
    // result.cancelled set. Not re-entrant: one run at a time per object.
    PipelineResult run(const std::string& path, const PipelineOptions& options);
    // Pipeline 1 from memory: generateScene(points, seed), fed to the sorter in batches.
    PipelineResult runGeneratedScene(std::uint64_t points, std::uint64_t seed,
                                     const PipelineOptions& options);
    // A new hierarchy from the kept sorted cloud with `options` (sortChunks is ignored):
    // no file is read. Throws std::logic_error when no complete sorted cloud is kept.
    PipelineResult rebuild(const BuildOptions& options);

    // Any thread: stops the current run at the next batch, chunk or fix level (or block of
    // the bounds pre-pass: the run then returns cancelled with the previous cloud and
    // hierarchy kept, since it never got to replace them). The request
    // stays until resetCancel(), so a cancel that races with the start of a run (issued
    // before the run's thread got going) still stops it: every later run returns at once,
    // cancelled, until the owner calls resetCancel() before starting the next one.
    void cancel();
    void resetCancel() { m_cancel.store(false); }
    // The flag cancel() sets, for a job its owner runs beside the pipeline's own (an export of
    // the kept hierarchy), so that one cancel() stops whichever runs.
    const std::atomic<bool>& cancelFlag() const { return m_cancel; }

    // Called as the bounds pre-pass of a cloud file advances, one call at a time, on the run's
    // thread or a oneTBB worker it waits for (see OpenOptions::onPrePassProgress); it may call
    // cancel(). progress() has the same numbers for pollers. Set it between runs, not during
    // one.
    using PrePassObserver =
        std::function<void(std::uint64_t bytesScanned, std::uint64_t fileBytes)>;
    void setPrePassObserver(PrePassObserver observer) { m_prePassObserver = std::move(observer); }

    // ---- Any thread. ----
    PipelineProgress progress() const;
    // The sorter's random sample while pipeline 1 reads (a COPC file: its hierarchy's top
    // levels instead, a uniform sample of the whole cloud from the moment it is opened);
    // before that, while a PLY or XYZ file is scanned for its bounds, a provisional one
    // (PreviewSample::provisional: positions in the unit cube of the sample's own bounds so
    // far); empty otherwise.
    PreviewSample preview() const;
    // Valid once the source is opened (cube, attributes, counts).
    std::optional<PipelineSource> source() const;
    // The sorted cloud of the current source (growing during a run, complete after one).
    std::shared_ptr<const SortedCloud> sortedCloud() const;
    // The hierarchy being built or last built; available as soon as its builder exists, so a
    // renderer can attach before the build ends. nullptr before the first run.
    std::shared_ptr<const Hierarchy> hierarchy() const;
    // The current builder's latest snapshot (empty statistics before the first run); for a
    // loaded .omh file, the statistics its header records.
    BuildStatistics statistics() const;
    // The parameters hierarchy() was built with (a loaded file's: from its header).
    BuildOptions hierarchyOptions() const;
    // True when a complete sorted cloud is kept, so rebuild() and exports work.
    bool hasCompleteCloud() const;
    // How many times a source was read (files and the generated scene; rebuild() reads none).
    std::uint64_t sourceReads() const { return m_sourceReads.load(std::memory_order_relaxed); }

private:
    PipelineResult runCloud(const std::string& path, const PipelineOptions& options);
    PipelineResult runSortedStream(const std::string& path, const PipelineOptions& options);
    PipelineResult runHierarchyFile(const std::string& path, const PipelineOptions& options);
    void beginRun(BuildPhase phase);
    void setSource(const PipelineSource& source, std::shared_ptr<const SortedCloud> cloud);
    std::shared_ptr<HierarchyBuilder> startBuilder(const BuildOptions& options);
    PipelineResult finishBuild(HierarchyBuilder& builder, PipelineResult result);
    // After the read: the sort's ranges into the builder (unless result.cancelled), then
    // finishBuild.
    PipelineResult sortIntoBuilder(IncrementalMortonSorter& sorter, HierarchyBuilder& builder,
                                   PipelineResult result);
    void setPhase(BuildPhase phase) { m_phase.store(static_cast<int>(phase)); }
    bool cancelled() const { return m_cancel.load(std::memory_order_relaxed); }

    PrePassObserver m_prePassObserver;
    std::atomic<bool> m_cancel{false};
    std::atomic<int> m_phase{static_cast<int>(BuildPhase::Idle)};
    std::atomic<std::uint64_t> m_pointsTotal{0};
    std::atomic<std::uint64_t> m_pointsRead{0};
    std::atomic<std::uint64_t> m_bytesScanned{0};
    std::atomic<std::uint64_t> m_bytesToScan{0};
    std::atomic<std::uint64_t> m_generation{0};
    std::atomic<std::uint64_t> m_sourceReads{0};
    std::atomic<std::uint64_t> m_sortRuns{0};
    std::atomic<bool> m_running{false};

    mutable std::mutex m_mutex; // guards the shared pointers and the source below
    std::optional<PipelineSource> m_source;
    std::shared_ptr<const SortedCloud> m_cloud;
    std::shared_ptr<const IncrementalMortonSorter> m_sorter; // only while pipeline 1 reads
    std::vector<glm::dvec3> m_provisional; // the bounds pre-pass's sample, source units
    // A COPC file's top levels (OpenOptions::onHierarchyPreview), in the cloud's unit cube.
    std::optional<PreviewSample> m_hierarchyPreview;
    std::shared_ptr<HierarchyBuilder> m_builder;
    // Pipeline 3: the loaded hierarchy and its statistics (from the file), without a builder.
    std::shared_ptr<const Hierarchy> m_loaded;
    BuildStatistics m_loadedStatistics;
    BuildOptions m_loadedOptions;
};

} // namespace omicron
