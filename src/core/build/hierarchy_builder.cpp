#include "build/hierarchy_builder.hpp"

#include "build/cut_invariants.hpp"
#include "build/leaf_runs.hpp"
#include "build/parent_sampler.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace omicron {

namespace {

// Input cut into leaves per pass, at most: bounds the latency of a pass (and of cancel()),
// so that a builder that fell behind still publishes in steps. Each pass also has a fixed
// cost that does not parallelise (the fork and join of its parallel loops, the classification
// and the commit on the master): measured interleaved on autzen_south, 2^18 held 2 threads to
// 1.71-1.75x of one, 2^20 reached 1.81-1.94x (and 2^21 no more). A 2^20 pass is about 1 ms.
constexpr std::size_t kMaxInsertPoints = std::size_t{1} << 20;
// Leaves written per parallel task (a full pass makes a few thousand).
constexpr std::size_t kLeafFillGrain = 256;

// What a worker makes of one sibling group, before the master publishes it.
struct ParentDraft {
    OctreeNode node; // sampleIndices not set: the sample is in the owning result
    std::uint32_t sampleOffset = 0;
    bool sampled = false;           // node stores its sample (its pointer set at commit)
    bool substituted = false;       // a placeholder became its leaf here
    bool risingPlaceholder = false; // no node: the placeholder moves up as `root`
    CutRoot root;
};

struct WorklistResult {
    std::vector<ParentDraft> drafts;
    // The drafts' stored samples. The commit hands the whole buffer to the hierarchy (no copy
    // on the master thread); the worker sizes it exactly once its groups are drafted
    // (sampleDrafts), so it neither grows nor is trimmed by a copy.
    SampleBuffer samples;
    bool ownsSplitGroup = false; // its last group continued into the next worklist
    void clear() {
        drafts.clear();
        samples.clear();
        ownsSplitGroup = false;
    }
};

// The nodes of a sibling group of `level`, adjacent in Morton order, hence in the level's array.
struct SiblingNodes {
    std::array<const OctreeNode*, 8> nodes{};
    std::size_t count = 0;
    std::span<const OctreeNode* const> span() const { return {nodes.data(), count}; }
};

SiblingNodes siblingNodes(const Hierarchy& hierarchy, int level, std::uint32_t first,
                          std::size_t count) {
    assert(count <= 8);
    SiblingNodes siblings;
    siblings.count = count;
    for (std::size_t c = 0; c < count; ++c) {
        siblings.nodes[c] = &hierarchy.node(level, first + c);
    }
    return siblings;
}

// The parent (or substituted leaf, or risen placeholder) replacing `group` of level
// parentLevel + 1. Reads only published-or-appended nodes and the cut: safe in parallel.
void draftParent(const Hierarchy& hierarchy, const ObliqueCut& cut, const BuildOptions& options,
                 int parentLevel, std::span<const CutRoot> group,
                 std::vector<ParentDraft>& drafts) {
    ParentDraft draft;
    if (group.front().placeholder) {
        // A placeholder's parent slot holds nothing else (the leaf it stands for had no other
        // child), so its group is always itself alone.
        assert(group.size() == 1);
        const Placeholder& placeholder = cut.placeholder(group.front().index);
        if (morton::level(placeholder.leafCode) != parentLevel) {
            draft.risingPlaceholder = true;
            draft.root = {group.front().code >> 3, group.front().index, true};
            drafts.push_back(draft);
            return;
        }
        OctreeNode& leaf = draft.node;
        leaf.code = placeholder.leafCode;
        leaf.coveredBegin = placeholder.coveredBegin;
        leaf.coveredCount = placeholder.coveredCount;
        leaf.flags = static_cast<std::uint8_t>(NodeFlag::Leaf) |
                     static_cast<std::uint8_t>(NodeFlag::Collapsed);
        leaf.pointCount = placeholder.coveredCount;
        draft.substituted = true;
        if (options.collapse == LeafCollapse::Paper) {
            // The stratified picks of its range: implicit (OctreeNode::heldPoint).
            leaf.pointCount = sampleSize(placeholder.coveredCount, options.ratio);
        }
        drafts.push_back(draft);
        return;
    }

    for (std::size_t c = 0; c < group.size(); ++c) {
        assert(!group[c].placeholder && group[c].index == group.front().index + c);
    }
    const SiblingNodes children =
        siblingNodes(hierarchy, parentLevel + 1, group.front().index, group.size());
    OctreeNode& parent = draft.node;
    parent.code = group.front().code >> 3;
    parent.firstChild = group.front().index;
    parent.childCount = static_cast<std::uint8_t>(group.size());
    parent.coveredBegin = children.nodes[0]->coveredBegin;
    std::uint64_t childPoints = 0;
    // When every child holds its whole covered range, together they hold the parent's, and the
    // stratified picks of it are a formula (OctreeNode::heldPoint): the sample is implicit.
    // Most parents of a build are one level above the leaves, and have no list to store.
    for (const OctreeNode* child : children.span()) {
        parent.coveredCount += child->coveredCount;
        childPoints += child->pointCount;
        draft.sampled = draft.sampled || !child->holdsRange();
    }
    parent.pointCount = sampleSize(childPoints, options.ratio);
    drafts.push_back(draft);
}

// Fills the stored samples of a worklist's drafts into one buffer of exactly their size.
void sampleDrafts(const Hierarchy& hierarchy, int parentLevel, WorklistResult& result) {
    std::uint32_t total = 0;
    for (ParentDraft& draft : result.drafts) {
        if (draft.sampled) {
            draft.sampleOffset = total;
            total += draft.node.pointCount;
        }
    }
    result.samples.resize(total);
    for (const ParentDraft& draft : result.drafts) {
        if (draft.sampled) {
            const OctreeNode& parent = draft.node;
            sampleChildren(
                siblingNodes(hierarchy, parentLevel + 1, parent.firstChild, parent.childCount)
                    .span(),
                std::span(result.samples).subspan(draft.sampleOffset, parent.pointCount));
        }
    }
}

} // namespace

// The parallel machinery, kept out of the header: the task arena that bounds the threads,
// per-thread scratch, and the buffers reused from pass to pass.
class HierarchyBuilder::Worker {
public:
    explicit Worker(int threads) : arena(threads > 0 ? threads : tbb::task_arena::automatic) {}

    tbb::task_arena arena;
    std::vector<WorklistResult> results;
    std::vector<LeafRun> runs;
    std::vector<CutRoot> roots;
};

HierarchyBuilder::HierarchyBuilder(std::shared_ptr<const SortedCloud> cloud,
                                   const BuildOptions& options)
    : m_options((validate(options), options)), m_cloud(std::move(cloud)),
      m_hierarchy(std::make_shared<Hierarchy>(m_cloud, options.maxLevel)), m_cut(options.maxLevel),
      m_worker(std::make_unique<Worker>(options.threads)),
      m_start(std::chrono::steady_clock::now()) {
    m_stats.levels.resize(static_cast<std::size_t>(options.maxLevel) + 1);
    m_stats.cloudBytes = m_cloud->bytesResident();
    m_stats.pointStorage = m_cloud->storage();
    m_publishedStats = m_stats;
    m_thread = std::thread([this] { run(); });
}

HierarchyBuilder::~HierarchyBuilder() {
    cancel();
    if (m_thread.joinable()) {
        m_thread.join();
    }
}

void HierarchyBuilder::onSortedRange(const SortedCloud& cloud, std::size_t begin, std::size_t end) {
    assert(&cloud == m_cloud.get() && end <= cloud.sortedEnd());
    (void)cloud;
    {
        std::lock_guard lock(m_inputMutex);
        assert(begin == m_available && !m_inputEnded);
        (void)begin;
        if (m_firstRangeSeconds < 0.0) {
            m_firstRangeSeconds = secondsSinceStart();
        }
        m_available = end;
        m_availableHint.store(end, std::memory_order_release);
    }
    m_inputChanged.notify_one();
}

SortedRangeConsumer HierarchyBuilder::consumer() {
    return [this](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
        onSortedRange(cloud, begin, end);
    };
}

void HierarchyBuilder::finish() {
    {
        std::lock_guard lock(m_inputMutex);
        m_inputEnded = true;
        m_inputEndSeconds = secondsSinceStart();
    }
    m_inputChanged.notify_one();
}

void HierarchyBuilder::cancel() {
    {
        std::lock_guard lock(m_inputMutex);
        m_cancel.store(true, std::memory_order_relaxed);
    }
    m_inputChanged.notify_one();
}

void HierarchyBuilder::wait() {
    std::unique_lock lock(m_doneMutex);
    m_doneChanged.wait(lock, [this] { return m_done; });
    if (m_error) {
        std::rethrow_exception(m_error);
    }
}

BuildStatistics HierarchyBuilder::statistics() const {
    std::lock_guard lock(m_statsMutex);
    return m_publishedStats;
}

double HierarchyBuilder::secondsSinceStart() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
}

void HierarchyBuilder::run() {
    try {
        m_worker->arena.execute([this] { buildLoop(); });
    } catch (...) {
        m_error = std::current_exception();
    }
    m_stats.creationSeconds = secondsSinceStart();
    m_stats.cancelled = !m_stats.complete;
    publishStatistics();
    {
        std::lock_guard lock(m_doneMutex);
        m_done = true;
    }
    m_doneChanged.notify_all();
}

void HierarchyBuilder::buildLoop() {
    bool passComplete = true;
    for (;;) {
        std::size_t available = 0;
        bool inputEnded = false;
        if (!waitForWork(passComplete, available, inputEnded)) {
            return;
        }
        insertInput(available, inputEnded);
        if (inputEnded && m_insertedEnd == available && !m_cut.closed()) {
            m_cut.close();
        }
        passComplete = fixPass();
        if (passComplete && m_cut.hasDelimiter()) {
            m_hierarchy->publishCutDelimiter(m_cut.delimiter());
        }
        if (m_options.checkInvariants) {
            checkInvariants(passComplete);
        }
        const bool complete = passComplete && m_cut.closed() && !cancelRequested();
        if (complete) {
            m_hierarchy->markComplete();
            m_stats.complete = true;
        }
        publishStatistics();
        if (complete || cancelRequested()) {
            return;
        }
    }
}

// Blocks until there is something to do; false when cancelled.
bool HierarchyBuilder::waitForWork(bool passComplete, std::size_t& available, bool& inputEnded) {
    std::unique_lock lock(m_inputMutex);
    if (passComplete && !m_inputBacklog) {
        m_inputChanged.wait(lock, [this] {
            return cancelRequested() || m_inputEnded || m_available != m_takenAvailable;
        });
    }
    available = m_available;
    inputEnded = m_inputEnded;
    m_takenAvailable = available;
    m_stats.firstRangeSeconds = m_firstRangeSeconds;
    m_stats.inputEndSeconds = m_inputEndSeconds;
    return !cancelRequested();
}

void HierarchyBuilder::insertInput(std::size_t available, bool inputEnded) {
    const int maxLevel = m_options.maxLevel;
    // Whole sibling groups only: leaf collapse must see a leaf's siblings, and a sparse leaf's
    // splat estimate borrows its siblings' points (Hierarchy::sparseSplatRegion).
    const int groupLevel = maxLevel - 1;
    Worker& worker = *m_worker;
    std::vector<LeafRun>& runs = worker.runs;
    runs.clear();
    // A cloud in a scratch file: what the last pass read may leave memory before this one.
    m_cloud->keepWithinBudget();
    const std::size_t end = m_cloud->visitPositions([&](const auto& positions) {
        const std::size_t cut = insertableEnd(positions, m_insertedEnd, available, inputEnded,
                                              groupLevel, kMaxInsertPoints);
        m_inputBacklog = insertableEnd(positions, cut, available, inputEnded, groupLevel,
                                       kMaxInsertPoints) > cut;
        findLeafRuns(positions, m_cloud->blockCodes(available), m_insertedEnd, cut, maxLevel, runs);
        return cut;
    });
    if (end == m_insertedEnd) {
        return;
    }

    // What each run becomes, in order on the master (cheap: no memory beyond the runs): a
    // leaf with the next node index or, under leaf collapse, a placeholder when it has no
    // sibling (the range holds whole sibling groups, so its neighbours tell).
    std::vector<CutRoot>& roots = worker.roots;
    roots.resize(runs.size());
    const bool collapse = m_options.collapse != LeafCollapse::Off;
    const std::size_t firstLeaf = m_hierarchy->builtNodeCount(maxLevel);
    std::size_t leaves = 0;
    std::uint64_t leafPoints = 0;
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const LeafRun& run = runs[i];
        const morton::Code parent = run.code >> 3;
        if (collapse && (i == 0 || (runs[i - 1].code >> 3) != parent) &&
            (i + 1 == runs.size() || (runs[i + 1].code >> 3) != parent)) {
            const std::uint32_t id = m_cut.addPlaceholder({parent, run.begin, run.count});
            roots[i] = {morton::span(parent, maxLevel), id, true};
            continue;
        }
        roots[i] = {run.code, static_cast<std::uint32_t>(firstLeaf + leaves), false};
        ++leaves;
        leafPoints += run.count;
    }
    LevelStatistics& leafLevel = m_stats.levels[maxLevel];
    leafLevel.nodes += leaves;
    leafLevel.leaves += leaves;
    leafLevel.points += leafPoints;
    m_stats.placeholdersCreated += runs.size() - leaves;
    m_stats.collapsedLeaves += runs.size() - leaves;

    publishLeaves(runs, roots, leaves);
    m_cut.concatenate(roots);
    m_insertedEnd = end;
    m_stats.inputPoints = end;
    recordMilestones(m_stats.milestonesSeconds, end, m_cloud->capacity(), secondsSinceStart());
}

// The leaves and the render front's hand-off (front.hpp): one insertion entry per run, in the
// same span order, naming the leaf itself (a collapsed leaf is not a node yet). Written in
// parallel into slots the arenas hand out (new cache lines, in a first build new pages too:
// the writes are the cost), then published, leaves first, so that an entry's maxLevel leaf is
// always published when the entry is. The entries' publication time is taken before the
// writes: a front's measured insertion delay may only err long.
void HierarchyBuilder::publishLeaves(std::span<const LeafRun> runs, std::span<const CutRoot> roots,
                                     std::size_t leaves) {
    const int maxLevel = m_options.maxLevel;
    m_hierarchy->extendNodes(maxLevel, leaves);
    const std::size_t firstInsertion = m_hierarchy->extendInsertions(runs.size());
    const auto publishedAt = std::chrono::steady_clock::now();
    const auto fill = [&](std::size_t i) {
        const LeafRun& run = runs[i];
        const CutRoot& root = roots[i];
        if (!root.placeholder) {
            OctreeNode leaf; // written whole: the slot is uninitialised memory
            leaf.code = run.code;
            leaf.coveredBegin = run.begin;
            leaf.coveredCount = run.count;
            leaf.pointCount = run.count;
            leaf.flags = static_cast<std::uint8_t>(NodeFlag::Leaf);
            m_hierarchy->builtNode(maxLevel, root.index) = leaf;
        }
        m_hierarchy->builtInsertion(firstInsertion + i) = {
            root.placeholder ? run.code >> 3 : run.code, run.begin, run.count, publishedAt};
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, runs.size(), kLeafFillGrain),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i < range.end(); ++i) {
                              fill(i);
                          }
                      });
    m_hierarchy->publishNodes(maxLevel);
    m_hierarchy->publishInsertions();
}

// One fix pass from maxLevel up; false when it stopped early (new input, or cancel).
bool HierarchyBuilder::fixPass() {
    ++m_stats.fixPasses;
    for (int level = m_options.maxLevel; level >= 1; --level) {
        fixLevel(level);
        if (cancelRequested()) {
            return false;
        }
        if (level > 1 && shouldStartNewPass(level - 1)) {
            ++m_stats.passesRestarted;
            return false;
        }
    }
    return true;
}

void HierarchyBuilder::fixLevel(int level) {
    Worker& worker = *m_worker;
    const std::span<const CutRoot> pending = m_cut.pendingRoots(level);
    const std::size_t worklistSize = m_options.worklistSize;
    const std::size_t worklists = (pending.size() + worklistSize - 1) / worklistSize;
    if (worker.results.size() < worklists) {
        worker.results.resize(worklists);
    }
    // A worklist owns the sibling groups whose first root it holds. A group cut by a worklist
    // boundary would give the paper's duplicate parents, one per worklist, each with part of
    // the children; here the owner takes the whole group, reading up to 7 roots past its end,
    // and the next worklist skips them: the duplicates are merged where they would arise, in
    // parallel, and no child is lost or moved afterwards.
    const auto sameParent = [&](std::size_t a, std::size_t b) {
        return (pending[a].code >> 3) == (pending[b].code >> 3);
    };
    const auto runWorklist = [&](std::size_t w) {
        WorklistResult& result = worker.results[w];
        result.clear();
        std::size_t first = w * worklistSize;
        std::size_t last = std::min(first + worklistSize, pending.size());
        while (first > 0 && first < last && sameParent(first - 1, first)) {
            ++first;
        }
        if (first == last) {
            return; // the whole worklist continues a group owned by an earlier one
        }
        if (last < pending.size() && sameParent(last - 1, last)) {
            result.ownsSplitGroup = true;
            while (last < pending.size() && sameParent(last - 1, last)) {
                ++last;
            }
        }
        forEachSiblingGroup(
            pending.subspan(first, last - first), [&](std::span<const CutRoot> group) {
                draftParent(*m_hierarchy, m_cut, m_options, level - 1, group, result.drafts);
            });
        sampleDrafts(*m_hierarchy, level - 1, result);
    };
    if (worklists == 1) {
        runWorklist(0);
    } else if (worklists > 1) {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, worklists, 1),
            [&](const tbb::blocked_range<std::size_t>& range) {
                for (std::size_t w = range.begin(); w < range.end(); ++w) {
                    runWorklist(w);
                }
            },
            tbb::simple_partitioner());
    }
    m_stats.worklists += worklists;

    // Commit in Morton order (worklist by worklist), then publish: no published node changes.
    std::vector<CutRoot>& parents = worker.roots;
    parents.clear();
    LevelStatistics& parentLevel = m_stats.levels[level - 1];
    for (std::size_t w = 0; w < worklists; ++w) {
        WorklistResult& result = worker.results[w];
        m_stats.duplicateParentsMerged += result.ownsSplitGroup ? 1 : 0;
        const std::uint32_t* samples = nullptr;
        if (!result.samples.empty()) {
            // The result is not reused before the next level: its buffer may move out.
            samples = m_hierarchy->adoptSamples(std::move(result.samples));
        }
        for (const ParentDraft& draft : result.drafts) {
            if (draft.risingPlaceholder) {
                parents.push_back(draft.root);
                continue;
            }
            OctreeNode node = draft.node;
            if (draft.sampled) {
                node.sampleIndices = samples + draft.sampleOffset;
            }
            parents.push_back({node.code,
                               static_cast<std::uint32_t>(m_hierarchy->appendNode(level - 1, node)),
                               false});
            ++parentLevel.nodes;
            parentLevel.points += node.pointCount;
            if (draft.substituted) {
                ++parentLevel.leaves;
                ++parentLevel.placeholdersSubstituted;
                ++m_stats.placeholdersSubstituted;
                m_stats.droppedPoints += node.coveredCount - node.pointCount;
            }
        }
    }
    m_hierarchy->publishNodes(level - 1);
    m_cut.completeLevel(level, parents);
    m_hierarchy->publishFixedThrough(level, m_cut.delimiter());
}

// The paper's multipass decision: leave this pass for a new one from maxLevel when the new
// input promises more work than the next level of this pass holds.
bool HierarchyBuilder::shouldStartNewPass(int nextLevel) const {
    if (m_cut.closed()) {
        return false;
    }
    const std::size_t available = m_availableHint.load(std::memory_order_acquire);
    if (available == m_takenAvailable && !m_inputBacklog) {
        return false;
    }
    const std::uint64_t leaves = std::max<std::uint64_t>(
        1, m_stats.levels[m_options.maxLevel].leaves + m_stats.collapsedLeaves);
    const std::uint64_t pointsPerLeaf = std::max<std::uint64_t>(1, m_insertedEnd / leaves);
    const std::uint64_t newLeaves = (available - m_insertedEnd) / pointsPerLeaf;
    return newLeaves >= m_options.worklistSize && newLeaves > m_cut.pendingRoots(nextLevel).size();
}

void HierarchyBuilder::checkInvariants(bool completePass) {
    if (!m_stats.invariantViolation.empty()) {
        return;
    }
    CutCheckContext context;
    context.ratio = m_options.ratio;
    context.collapse = m_options.collapse;
    context.insertedPoints = m_insertedEnd;
    context.requireCompleteFix = completePass;
    m_stats.invariantViolation = checkCutInvariants(m_cut, *m_hierarchy, context);
#ifdef OMICRON_CHECK_INVARIANTS
    if (!m_stats.invariantViolation.empty()) {
        std::fprintf(stderr, "omicron: cut invariant violated: %s\n",
                     m_stats.invariantViolation.c_str());
        std::abort();
    }
#endif
}

void HierarchyBuilder::publishStatistics() {
    // Walks L_C once per pass: after a fix the lists hold only the boundary, a small part of
    // the nodes, so this costs little next to the pass itself.
    for (int level = 0; level <= m_options.maxLevel; ++level) {
        LevelStatistics& levelStats = m_stats.levels[static_cast<std::size_t>(level)];
        const std::span<const CutRoot> roots = m_cut.roots(level);
        levelStats.cutRoots = roots.size();
        levelStats.placeholdersPending = static_cast<std::uint64_t>(std::count_if(
            roots.begin(), roots.end(), [](const CutRoot& r) { return r.placeholder; }));
    }
    m_stats.cloudBytes = m_cloud->bytesResident(); // a packed store grows with the input
    m_stats.nodeBytes = m_hierarchy->nodeBytes();
    m_stats.sampleBytes = m_hierarchy->sampleBytes();
    m_stats.splatBytes = m_hierarchy->splatBytes();
    std::lock_guard lock(m_statsMutex);
    m_publishedStats = m_stats;
}

} // namespace omicron
