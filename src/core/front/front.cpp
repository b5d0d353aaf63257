// Front: intake of what the builder published, and the sweep (substitution, prune by
// threshold and frustum, branch candidates). Branching and the point budget run at the end of
// each call: front_budget.cpp. The checker: front_invariants.cpp.
#include "front/front_impl.hpp"

#include <cassert>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace omicron {

namespace {

using Clock = std::chrono::steady_clock;

// The clock is read once per this many entries: a read costs about as much as an entry.
constexpr unsigned kEntriesPerClockRead = 32;

} // namespace

std::optional<std::size_t> ParentCursor::find(const Hierarchy& hierarchy, morton::Code code,
                                              std::size_t count) {
    const int level = morton::level(code);
    std::size_t low = std::min(m_next[level], count);
    // Everything before `low` must be below `code`; a walk that went back starts over.
    if (low > 0 && hierarchy.node(level, low - 1).code >= code) {
        low = 0;
    }
    // Gallop forward, then bisect: O(log distance) from the previous parent of this level.
    std::size_t high = low, step = 1;
    while (high < count && hierarchy.node(level, high).code < code) {
        low = high + 1;
        high += step;
        step *= 2;
    }
    high = std::min(high, count);
    while (low < high) {
        const std::size_t mid = low + (high - low) / 2;
        if (hierarchy.node(level, mid).code < code) {
            low = mid + 1;
        } else {
            high = mid;
        }
    }
    m_next[level] = low;
    if (low < count && hierarchy.node(level, low).code == code) {
        return low;
    }
    return std::nullopt;
}

Front::Impl::Impl(std::shared_ptr<const Hierarchy> sharedHierarchy)
    : shared(std::move(sharedHierarchy)), hierarchy(*shared), residency(shared->residency()),
      substitution(shared->maxLevel()) {}

void Front::Impl::loadPublished() {
    cut = hierarchy.publishedCut();
    for (int level = 0; level <= hierarchy.maxLevel(); ++level) {
        nodeCounts[level] = hierarchy.nodeCount(level);
    }
}

void Front::Impl::takeInsertions(FrontEvaluation& result) {
    // A hierarchy complete before the front saw any leaf (a finished build, a file being
    // loaded top-down) is entered from its root; a loader publishes the root after marking
    // the hierarchy complete, so wait for it.
    if (mode != Mode::TopDown && insertionsTaken == 0 && cut.complete) {
        // Paged points: the root enters once it can be drawn.
        if (nodeCounts[0] > 0 && wantResident(0, 0, std::numeric_limits<double>::max())) {
            mode = Mode::TopDown;
            entries.assign(1, FrontEntry{morton::kRoot, 0, false, false});
            levelCounts.fill(0);
            levelCounts[0] = 1;
        }
        return;
    }
    if (mode == Mode::TopDown) {
        return;
    }
    mode = Mode::BottomUp;
    // insertPlaceholder: appending keeps 2.1, the log is in span order and every entry
    // follows all the front holds (a front node's subtree was concatenated before it).
    const std::size_t count = hierarchy.insertionCount();
    for (std::size_t i = insertionsTaken; i < count; ++i) {
        const morton::Code leaf = hierarchy.insertion(i).leafCode;
        entries.push_back(FrontEntry{leaf, static_cast<std::uint32_t>(i), true, false});
        ++levelCounts[static_cast<std::size_t>(morton::level(leaf))];
        substitution.add(leaf, static_cast<std::uint32_t>(i), evaluations);
    }
    result.placeholdersInserted = count - insertionsTaken;
    placeholders += count - insertionsTaken;
    insertionsTaken = count;
}

void Front::Impl::startSweep(FrontEvaluation&) {
    sweepRunning = true;
    sweepPosition = 0;
    substitutionLevel = mode == Mode::BottomUp ? substitution.chooseLevel() : -1;
    sweepParents.reset();
}

void Front::Impl::account(const FrontEntry& entry, int sign) {
    if (!entry.visible || entry.placeholder) {
        return;
    }
    const std::uint32_t points = hierarchy.node(entry.level(), entry.index).pointCount;
    if (sign > 0) {
        ++visibleNodes;
        visiblePoints += points;
    } else {
        --visibleNodes;
        visiblePoints -= points;
    }
}

bool Front::Impl::childrenReady(const OctreeNode& node, int level) const {
    if (node.childCount == 0 || level >= hierarchy.maxLevel() ||
        std::size_t{node.firstChild} + node.childCount > nodeCounts[level + 1]) {
        return false;
    }
    // Siblings share their grandparent, so one child's settledness is all of theirs.
    return settled(hierarchy.node(level + 1, node.firstChild).code);
}

bool Front::Impl::childrenResident(const OctreeNode& node, int level) const {
    for (std::uint32_t child = 0; child < node.childCount; ++child) {
        if (!hierarchy.pointsResident(level + 1, std::size_t{node.firstChild} + child)) {
            return false;
        }
    }
    return true;
}

void Front::Impl::requestChildren(const OctreeNode& node, int level, double priority) {
    for (std::uint32_t child = 0; child < node.childCount; ++child) {
        // Every missing child at once: they load while the parent stays drawn.
        wantResident(level + 1, std::size_t{node.firstChild} + child, priority);
    }
}

void Front::Impl::holdEntries() {
    if (residency == nullptr) {
        return;
    }
    for (const FrontEntry& entry : entries) {
        if (!entry.placeholder) {
            residency->hold(entry.level(), entry.index);
        }
    }
    residency->endFrame();
}

// One segment of the sweep, from sweepPosition until the end or the CPU budget; true when it
// reached the end. Works in place: each entry read yields at most one entry written.
bool Front::Impl::sweep(const FrontOptions& options, FrontEvaluation& result) {
    const bool timed = options.cpuBudgetMs > 0.0;
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double, std::milli>(options.cpuBudgetMs));
    std::size_t read = sweepPosition, written = sweepPosition;
    std::size_t groupsCheckedEnd = read; // entries below were already tried as group starts
    unsigned sinceClockRead = 0;
    while (read < entries.size()) {
        if (timed && ++sinceClockRead == kEntriesPerClockRead) {
            sinceClockRead = 0;
            if (Clock::now() >= deadline) {
                break;
            }
        }
        FrontEntry entry = entries[read];
        const int level = entry.level();
        if (entry.placeholder) {
            if (level != substitutionLevel || !substitution.headIsReady(level, entry.code)) {
                entries[written++] = entry;
                ++read;
                continue;
            }
            const FrontSubstitution::Leaf& leaf = substitution.takeHead(level);
            delaysSeconds.push_back(std::chrono::duration<double>(
                                        Clock::now() - hierarchy.insertion(leaf.logIndex).publishedAt)
                                        .count());
            delaysEvaluations.push_back(static_cast<std::uint32_t>(evaluations - leaf.readyEval));
            entry = FrontEntry{leaf.code, leaf.nodeIndex, false, false};
            --placeholders;
            ++result.substituted;
        } else if (read >= groupsCheckedEnd && level > 0) {
            // prune: the sibling group starting here, if complete, by its parent. Siblings
            // are adjacent (2.1); a group whose first members were written already is not
            // complete here and waits for the next sweep.
            const morton::Code parentCode = entry.code >> 3;
            std::size_t end = read + 1;
            while (end < entries.size() && !entries[end].placeholder &&
                   (entries[end].code >> 3) == parentCode) {
                ++end;
            }
            groupsCheckedEnd = end;
            if (settled(parentCode)) {
                const auto parentIndex =
                    sweepParents.find(hierarchy, parentCode, nodeCounts[level - 1]);
                if (parentIndex &&
                    hierarchy.node(level - 1, *parentIndex).childCount == end - read) {
                    const CellBox box = cellBox(parentCode);
                    FrontEntry parent{parentCode, static_cast<std::uint32_t>(*parentIndex), false,
                                      intersectsFrustum(frustum, box)};
                    const double parentSizePx = projectedSizePx(box, camera);
                    // Out of view, a group only makes the front longer: prune it whatever
                    // its size (paged points: once the parent is in memory; out of view it
                    // loads after what is seen).
                    if ((!parent.visible || parentSizePx < thresholdPx) &&
                        wantResident(level - 1, *parentIndex, parent.visible ? parentSizePx : 0.0)) {
                        for (std::size_t member = read; member < end; ++member) {
                            account(entries[member], -1);
                        }
                        account(parent, +1);
                        levelCounts[static_cast<std::size_t>(level)] -= end - read;
                        ++levelCounts[static_cast<std::size_t>(level - 1)];
                        entries[written++] = parent;
                        read = end;
                        ++result.pruned;
                        continue;
                    }
                }
            }
        }
        account(entry, -1);
        const CellBox box = cellBox(entry.code);
        entry.visible = intersectsFrustum(frustum, box);
        account(entry, +1);
        entries[written++] = entry;
        ++read;
        if (entry.visible) {
            const OctreeNode& node = hierarchy.node(level, entry.index);
            if (childrenReady(node, level)) {
                const double sizePx = projectedSizePx(box, camera);
                if (sizePx > thresholdPx) {
                    candidates.push_back({written - 1, sizePx});
                }
            }
        }
    }
    const bool finished = read == entries.size();
    entries.erase(entries.begin() + static_cast<std::ptrdiff_t>(written),
                  entries.begin() + static_cast<std::ptrdiff_t>(read));
    sweepPosition = finished ? 0 : written;
    return finished;
}

Front::Front(std::shared_ptr<const Hierarchy> hierarchy)
    : m_impl(std::make_unique<Impl>(std::move(hierarchy))) {}

Front::~Front() = default;
Front::Front(Front&&) noexcept = default;
Front& Front::operator=(Front&&) noexcept = default;

FrontEvaluation Front::evaluate(const FrontCamera& camera, const FrontOptions& options) {
    const auto start = Clock::now();
    Impl& state = *m_impl;
    FrontEvaluation result;
    ++state.evaluations;
    state.camera = camera;
    state.frustum = frustumPlanes(camera.viewProjection);
    state.frustum.clip = camera.clip;
    state.thresholdPx = options.projectionThresholdPx;
    state.loadPublished();
    state.takeInsertions(result);
    if (state.mode == Impl::Mode::BottomUp) {
        state.substitution.updateReady(state.hierarchy, state.cut, state.nodeCounts,
                                       state.evaluations);
    }
    if (!state.sweepRunning) {
        state.startSweep(result);
    }
    state.candidates.clear();
    result.finishedSweep = state.sweep(options, result);
    state.sweepRunning = !result.finishedSweep;
    state.applyBudget(options, result);
    state.holdEntries();

    result.substitutionLevel = state.substitutionLevel;
    result.visibleNodes = state.visibleNodes;
    result.visiblePoints = static_cast<std::size_t>(state.visiblePoints);
    result.frontSize = state.entries.size();
    result.placeholders = state.placeholders;
    result.cpuMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
#ifdef OMICRON_CHECK_INVARIANTS
    const std::string violation = checkInvariants();
    if (!violation.empty()) {
        std::fprintf(stderr, "omicron: front invariant violated: %s\n", violation.c_str());
        std::abort();
    }
#endif
    return result;
}

std::span<const FrontEntry> Front::entries() const { return m_impl->entries; }

std::size_t Front::placeholderCount() const { return m_impl->placeholders; }

std::span<const std::size_t> Front::entriesPerLevel() const {
    return std::span<const std::size_t>(m_impl->levelCounts)
        .first(static_cast<std::size_t>(m_impl->hierarchy.maxLevel()) + 1);
}

const Hierarchy& Front::hierarchy() const { return m_impl->hierarchy; }

std::vector<double> Front::takeSubstitutionDelays() {
    std::vector<double> delays;
    delays.swap(m_impl->delaysSeconds);
    return delays;
}

std::vector<std::uint32_t> Front::takeSubstitutionEvaluationDelays() {
    std::vector<std::uint32_t> delays;
    delays.swap(m_impl->delaysEvaluations);
    return delays;
}

} // namespace omicron
