// The end of every evaluate() call: the branches the sweep asked for, the largest projection
// first, as far as the point budget allows, and coarsening when the front holds too many
// points (as Potree's point budget does, but incrementally: the front is not rebuilt from
// the root). Everything here changes the front in one rebuild pass.
#include "front/front_impl.hpp"

#include <algorithm>
#include <cassert>
#include <limits>

namespace omicron {

namespace {

// Visible points of a node's children (computed as the rebuild will).
std::int64_t childrenVisiblePoints(const Hierarchy& hierarchy, const FrustumPlanes& frustum,
                                   const OctreeNode& node) {
    const int childLevel = node.level() + 1;
    std::int64_t points = 0;
    for (std::uint32_t c = 0; c < node.childCount; ++c) {
        const OctreeNode& child = hierarchy.node(childLevel, node.firstChild + c);
        if (intersectsFrustum(frustum, cellBox(child.code))) {
            points += child.pointCount;
        }
    }
    return points;
}

} // namespace

void Front::Impl::collectPrunableGroups(double parentSizeBelowPx) {
    groups.clear();
    ParentCursor parents;
    parents.reset();
    std::size_t i = 0;
    while (i < entries.size()) {
        const FrontEntry& first = entries[i];
        if (first.placeholder || first.level() == 0) {
            ++i;
            continue;
        }
        const morton::Code parentCode = first.code >> 3;
        std::size_t end = i + 1;
        while (end < entries.size() && !entries[end].placeholder &&
               (entries[end].code >> 3) == parentCode) {
            ++end;
        }
        const int parentLevel = first.level() - 1;
        if (settled(parentCode)) {
            const auto parentIndex = parents.find(hierarchy, parentCode, nodeCounts[parentLevel]);
            if (parentIndex) {
                const OctreeNode& parent = hierarchy.node(parentLevel, *parentIndex);
                const CellBox box = cellBox(parentCode);
                const double parentSizePx = projectedSizePx(box, camera);
                if (parent.childCount == end - i) {
                    PrunableGroup group;
                    group.parentLevel = parentLevel;
                    group.parentResident = hierarchy.pointsResident(parentLevel, *parentIndex);
                    group.position = i;
                    group.members = static_cast<std::uint32_t>(end - i);
                    group.parentIndex = static_cast<std::uint32_t>(*parentIndex);
                    group.parentVisible = intersectsFrustum(frustum, box);
                    group.parentSizePx = parentSizePx;
                    for (std::size_t member = i; member < end; ++member) {
                        const FrontEntry& entry = entries[member];
                        if (entry.visible) {
                            group.pointsFreed +=
                                hierarchy.node(entry.level(), entry.index).pointCount;
                        }
                    }
                    if (group.parentVisible) {
                        group.pointsFreed -= parent.pointCount;
                    }
                    // Groups that free nothing, or look at least as large as what they would
                    // make room for, are never pruned: leave them out of the sort.
                    if (group.pointsFreed > 0 && group.parentSizePx < parentSizeBelowPx) {
                        groups.push_back(group);
                    }
                }
            }
        }
        i = end;
    }
    // Smallest on screen first: what coarsening costs least to look at.
    std::sort(groups.begin(), groups.end(), [](const PrunableGroup& a, const PrunableGroup& b) {
        return a.parentSizePx < b.parentSizePx;
    });
}

void Front::Impl::applyBudget(const FrontOptions& options, FrontEvaluation& result) {
    const std::uint64_t budget = options.pointBudget == 0
                                     ? std::numeric_limits<std::uint64_t>::max()
                                     : static_cast<std::uint64_t>(options.pointBudget);
    if (visiblePoints > budget) {
        // Coarsen: prune the smallest groups that free points until the front fits; a pruned
        // group's parent may complete a group one level up, hence the rounds.
        for (int round = 0; round <= hierarchy.maxLevel() && visiblePoints > budget; ++round) {
            collectPrunableGroups(std::numeric_limits<double>::infinity());
            operations.clear();
            std::int64_t excess = static_cast<std::int64_t>(visiblePoints - budget);
            for (const PrunableGroup& group : groups) {
                if (group.pointsFreed <= 0 || !prunableNow(group)) {
                    continue;
                }
                operations.push_back({group.position, group.members, group.parentIndex, false});
                excess -= group.pointsFreed;
                if (excess <= 0) {
                    break;
                }
            }
            if (operations.empty()) {
                break;
            }
            rebuild(operations, result);
        }
        result.overBudget = visiblePoints > budget;
        return;
    }
    if (candidates.empty()) {
        return;
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const BranchCandidate& a, const BranchCandidate& b) { return a.sizePx > b.sizePx; });
    // marks: 1 = branched, 2 = pruned to make room (or kept for a branch waiting for its
    // children), 3 = a branch waiting for its children's points.
    marks.assign(entries.size(), 0);
    operations.clear();
    std::int64_t allowance = static_cast<std::int64_t>(std::min<std::uint64_t>(
        budget - visiblePoints, std::numeric_limits<std::int64_t>::max() / 2));
    // A group may make room for a candidate unless it holds the candidate itself or an entry
    // already branched or pruned in this pass.
    const auto usableFor = [&](const PrunableGroup& group, const BranchCandidate& candidate) {
        const auto begin = static_cast<std::ptrdiff_t>(group.position);
        const auto end = static_cast<std::ptrdiff_t>(group.position + group.members);
        return group.pointsFreed > 0 && group.parentResident &&
               !(candidate.position >= group.position &&
                 candidate.position < group.position + group.members) &&
               std::all_of(marks.begin() + begin, marks.begin() + end,
                           [](std::uint8_t mark) { return mark == 0; });
    };
    bool groupsCollected = false, makeRoom = true;
    std::size_t nextGroup = 0;
    for (const BranchCandidate& candidate : candidates) {
        if (marks[candidate.position] != 0) {
            continue;
        }
        const FrontEntry& entry = entries[candidate.position];
        const OctreeNode& node = hierarchy.node(entry.level(), entry.index);
        const std::int64_t added = childrenVisiblePoints(hierarchy, frustum, node) -
                                   std::int64_t{node.pointCount};
        // Paged points: a branch whose children are not in memory yet is planned as if it
        // were made (its room reserved, groups it would prune kept from others) and its
        // children asked for; it is made in a later evaluation, once they have arrived. So a
        // frame asks only for what the budget would draw, and draws only what is resident.
        const bool resident = residency == nullptr || childrenResident(node, entry.level());
        if (added > allowance && makeRoom) {
            // Make room by pruning groups that look smaller than this node: detail moves to
            // where it shows most. Stable from sweep to sweep: the pruned parent is smaller
            // than this node, so it cannot win its place back from this node's children.
            if (!groupsCollected) {
                collectPrunableGroups(candidates.front().sizePx);
                groupsCollected = true;
            }
            std::int64_t freed = 0;
            std::size_t last = nextGroup;
            for (; last < groups.size() && added > allowance + freed &&
                   groups[last].parentSizePx < candidate.sizePx;
                 ++last) {
                const PrunableGroup& group = groups[last];
                const bool usable = usableFor(group, candidate);
                if (usable) {
                    freed += group.pointsFreed;
                } else if (!group.parentResident) {
                    prunableNow(group); // asks for the parent: usable in a later evaluation
                }
            }
            if (added <= allowance + freed) {
                for (; nextGroup < last; ++nextGroup) {
                    const PrunableGroup& group = groups[nextGroup];
                    const bool usable = usableFor(group, candidate);
                    if (usable) {
                        std::fill_n(marks.begin() + static_cast<std::ptrdiff_t>(group.position),
                                    group.members, std::uint8_t{2});
                        if (resident) {
                            operations.push_back(
                                {group.position, group.members, group.parentIndex, false});
                        }
                        allowance += group.pointsFreed;
                    }
                }
            } else {
                // Nothing smaller frees enough for this node, nor for smaller ones after
                // it (they may prune even less): keep the rest to the allowance.
                makeRoom = false;
            }
        }
        if (added <= allowance) {
            if (resident) {
                marks[candidate.position] = 1;
                operations.push_back({candidate.position, 0, entry.index, true});
            } else {
                marks[candidate.position] = 3;
                requestChildren(node, entry.level(), candidate.sizePx);
            }
            allowance -= added;
        }
    }
    if (!operations.empty()) {
        rebuild(operations, result);
    }
}

// Applies `ops` (disjoint) in one pass, keeping the sweep's resume point on
// the same entry.
void Front::Impl::rebuild(std::vector<Rebuild>& ops, FrontEvaluation& result) {
    std::sort(ops.begin(), ops.end(),
              [](const Rebuild& a, const Rebuild& b) { return a.position < b.position; });
    rebuilt.clear();
    rebuilt.reserve(entries.size() + 8 * ops.size());
    bool resumeMapped = !sweepRunning;
    std::size_t resume = 0;
    std::size_t copied = 0;
    const auto copyUpTo = [&](std::size_t end) {
        if (!resumeMapped && sweepPosition >= copied && sweepPosition < end) {
            resume = rebuilt.size() + (sweepPosition - copied);
            resumeMapped = true;
        }
        rebuilt.insert(rebuilt.end(), entries.begin() + static_cast<std::ptrdiff_t>(copied),
                       entries.begin() + static_cast<std::ptrdiff_t>(end));
        copied = end;
    };
    for (const Rebuild& op : ops) {
        assert(op.position >= copied);
        copyUpTo(op.position);
        const FrontEntry& first = entries[op.position];
        if (op.branch) {
            if (!resumeMapped && sweepPosition == op.position) {
                resume = rebuilt.size();
                resumeMapped = true;
            }
            account(first, -1);
            const OctreeNode& node = hierarchy.node(first.level(), op.nodeIndex);
            --levelCounts[static_cast<std::size_t>(first.level())];
            levelCounts[static_cast<std::size_t>(first.level()) + 1] += node.childCount;
            for (std::uint32_t c = 0; c < node.childCount; ++c) {
                const std::uint32_t index = node.firstChild + c;
                const morton::Code code = hierarchy.node(first.level() + 1, index).code;
                const FrontEntry child{code, index, false,
                                       intersectsFrustum(frustum, cellBox(code))};
                account(child, +1);
                rebuilt.push_back(child);
            }
            copied = op.position + 1;
            ++result.branched;
            continue;
        }
        // A group the sweep has not reached is evaluated as the parent; one it is inside
        // counts as done.
        if (!resumeMapped && sweepPosition >= op.position &&
            sweepPosition < op.position + op.members) {
            resume = rebuilt.size() + (sweepPosition == op.position ? 0 : 1);
            resumeMapped = true;
        }
        for (std::size_t member = op.position; member < op.position + op.members; ++member) {
            account(entries[member], -1);
        }
        const morton::Code parentCode = first.code >> 3;
        const FrontEntry parent{parentCode, op.nodeIndex, false,
                                intersectsFrustum(frustum, cellBox(parentCode))};
        account(parent, +1);
        levelCounts[static_cast<std::size_t>(first.level())] -= op.members;
        ++levelCounts[static_cast<std::size_t>(first.level()) - 1];
        rebuilt.push_back(parent);
        copied = op.position + op.members;
        ++result.pruned;
    }
    copyUpTo(entries.size());
    if (!resumeMapped) {
        resume = rebuilt.size(); // the sweep stopped at the very end: nothing left to map
    }
    entries.swap(rebuilt);
    if (sweepRunning) {
        sweepPosition = resume;
    }
    ops.clear();
}

} // namespace omicron
