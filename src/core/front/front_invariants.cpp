// The front's checker: invariants 2.1 and 2.2 of the paper, plus what makes them mean
// something here: every entry is a published node or a placeholder of a logged leaf, the
// entries' covered input ranges tile the input seen so far (no leaf lost or drawn twice), the
// placeholders match the substitution lists, and the visible counts add up.
#include "front/front_impl.hpp"

#include <sstream>

namespace omicron {

namespace {

std::string describe(const FrontEntry& entry, std::size_t position) {
    std::ostringstream out;
    out << "entry " << position << " (code " << entry.code << ", level " << entry.level()
        << (entry.placeholder ? ", placeholder" : "") << ")";
    return out.str();
}

} // namespace

std::string Front::checkInvariants() const {
    const Impl& state = *m_impl;
    const Hierarchy& hierarchy = state.hierarchy;
    const int maxLevel = hierarchy.maxLevel();
    const std::span<const FrontEntry> front = state.entries;
    std::array<std::size_t, morton::kMaxLevel + 1> placeholdersSeen{};
    std::array<std::size_t, morton::kMaxLevel + 1> entriesPerLevel{};
    std::uint64_t coveredEnd = 0, visiblePoints = 0;
    std::size_t visibleNodes = 0, placeholders = 0;
    morton::Code previousSpan = 0;
    // A loaded .omh hierarchy's nodes hold their own points (CloudOrder::NodeOrder), not the
    // range of their subtree's input: covered ranges tile the input only for a built one.
    const bool tilesInput = hierarchy.cloud().order() == CloudOrder::Morton;
    for (std::size_t i = 0; i < front.size(); ++i) {
        const FrontEntry& entry = front[i];
        if (!morton::isValid(entry.code) || entry.level() > maxLevel) {
            return describe(entry, i) + ": not a code of this hierarchy";
        }
        const morton::Code span = morton::span(entry.code, maxLevel);
        if (i > 0 && span <= previousSpan) {
            return "2.1: " + describe(entry, i) + " does not follow the previous entry in span order";
        }
        previousSpan = span;
        const int level = entry.level();
        ++entriesPerLevel[static_cast<std::size_t>(level)];
        std::uint64_t coveredBegin = 0, coveredCount = 0;
        if (entry.placeholder) {
            ++placeholders;
            if (entry.visible) {
                return describe(entry, i) + ": a placeholder marked visible";
            }
            if (entry.index >= state.insertionsTaken ||
                hierarchy.insertion(entry.index).leafCode != entry.code) {
                return describe(entry, i) + ": a placeholder of no logged leaf";
            }
            const auto waiting = state.substitution.waiting(level);
            const std::size_t k = placeholdersSeen[level]++;
            if (k >= waiting.size() || waiting[k].code != entry.code ||
                waiting[k].logIndex != entry.index) {
                return describe(entry, i) + ": placeholders and the level's substitution list "
                                            "are out of step";
            }
            coveredBegin = hierarchy.insertion(entry.index).coveredBegin;
            coveredCount = hierarchy.insertion(entry.index).coveredCount;
        } else {
            if (entry.index >= hierarchy.nodeCount(level) ||
                hierarchy.node(level, entry.index).code != entry.code) {
                return describe(entry, i) + ": not a published node";
            }
            // The front's own view of the cut: the one its decisions were made with.
            if (!Hierarchy::isSettled(entry.code, state.cut, maxLevel)) {
                return "2.2: " + describe(entry, i) + " is a root of the cut or a child of one";
            }
            // Paged points: the front holds only nodes that can be drawn.
            if (!hierarchy.pointsResident(level, entry.index)) {
                return describe(entry, i) + ": its points are not in memory";
            }
            const OctreeNode& node = hierarchy.node(level, entry.index);
            coveredBegin = node.coveredBegin;
            coveredCount = node.coveredCount;
            if (entry.visible) {
                ++visibleNodes;
                visiblePoints += node.pointCount;
            }
        }
        if (tilesInput && coveredBegin != coveredEnd) {
            std::ostringstream out;
            out << describe(entry, i) << " covers input from " << coveredBegin << ", expected "
                << coveredEnd << " (a leaf lost or held twice)";
            return out.str();
        }
        coveredEnd += coveredCount;
    }
    std::uint64_t expectedEnd = 0;
    if (state.mode == Impl::Mode::TopDown) {
        expectedEnd = hierarchy.node(0, 0).coveredCount;
    } else if (state.insertionsTaken > 0) {
        const CutInsertion& last = hierarchy.insertion(state.insertionsTaken - 1);
        expectedEnd = std::uint64_t{last.coveredBegin} + last.coveredCount;
    }
    if (tilesInput && coveredEnd != expectedEnd) {
        std::ostringstream out;
        out << "the front covers input up to " << coveredEnd << ", expected " << expectedEnd;
        return out.str();
    }
    for (int level = 0; level <= maxLevel; ++level) {
        if (placeholdersSeen[level] != state.substitution.waiting(level).size()) {
            return "level " + std::to_string(level) +
                   ": a leaf waits for substitution without a placeholder in the front";
        }
    }
    if (placeholders != state.placeholders) {
        return "placeholder count out of step";
    }
    if (visibleNodes != state.visibleNodes || visiblePoints != state.visiblePoints) {
        return "visible node or point count out of step";
    }
    if (entriesPerLevel != state.levelCounts) {
        return "entries per level out of step";
    }
    return {};
}

} // namespace omicron
