#include "build/cut_invariants.hpp"

#include "build/parent_sampler.hpp"

#include <algorithm>
#include <array>
#include <sstream>
#include <vector>

namespace omicron {

namespace {

std::string hex(morton::Code code) {
    std::ostringstream out;
    out << "0x" << std::hex << code;
    return out.str();
}

std::string describe(int level, std::size_t index, morton::Code code) {
    return "node " + hex(code) + " (level " + std::to_string(level) + ", index " +
           std::to_string(index) + ")";
}

class Checker {
public:
    Checker(const ObliqueCut& cut, const Hierarchy& hierarchy, const CutCheckContext& context)
        : m_cut(cut), m_hierarchy(hierarchy), m_context(context), m_maxLevel(hierarchy.maxLevel()) {
    }

    std::string run() {
        if (m_cut.maxLevel() != m_maxLevel) {
            return "cut and hierarchy disagree on maxLevel";
        }
        if (!checkLevelOrder() || !checkLists() || !checkSubtrees() || !checkTiling()) {
            return m_error;
        }
        return {};
    }

private:
    struct Coverage {
        std::uint64_t begin, count;
        morton::Code span;
    };

    bool fail(std::string message) {
        m_error = std::move(message);
        return false;
    }

    bool checkLevelOrder() {
        m_visited.resize(static_cast<std::size_t>(m_maxLevel) + 1);
        for (int level = 0; level <= m_maxLevel; ++level) {
            const std::size_t count = m_hierarchy.nodeCount(level);
            m_visited[level].assign(count, false);
            for (std::size_t i = 0; i < count; ++i) {
                const OctreeNode& node = m_hierarchy.node(level, i);
                if (!morton::isValid(node.code) || node.level() != level) {
                    return fail(describe(level, i, node.code) + " is stored in the wrong level");
                }
                if (i > 0 && m_hierarchy.node(level, i - 1).code >= node.code) {
                    return fail(describe(level, i, node.code) +
                                " breaks the Morton order of its level");
                }
            }
        }
        return true;
    }

    bool checkLists() {
        if (!m_cut.hasDelimiter()) {
            for (int level = 0; level <= m_maxLevel; ++level) {
                if (!m_cut.roots(level).empty() || m_hierarchy.nodeCount(level) != 0) {
                    return fail("a cut without m_C holds roots or nodes");
                }
            }
            return m_context.insertedPoints == 0 ||
                   fail("points were inserted but the cut has no m_C");
        }
        const morton::Code delimiter = m_cut.delimiter();
        if (!morton::isValid(delimiter) || morton::level(delimiter) != m_maxLevel) {
            return fail("1.1: m_C " + hex(delimiter) + " is not a code at level " +
                        std::to_string(m_maxLevel));
        }
        for (int level = 1; level <= m_maxLevel; ++level) {
            const morton::Code fixed = m_cut.fixedThrough(level);
            if (m_context.requireCompleteFix && fixed != delimiter) {
                return fail("fix incomplete: level " + std::to_string(level) + " fixed through " +
                            hex(fixed) + ", m_C is " + hex(delimiter));
            }
            if (fixed > delimiter ||
                (level < m_maxLevel && fixed > m_cut.fixedThrough(level + 1))) {
                return fail("level " + std::to_string(level) +
                            " was fixed with a delimiter beyond the level below it");
            }
        }
        for (int level = 0; level <= m_maxLevel; ++level) {
            const auto roots = m_cut.roots(level);
            for (std::size_t r = 0; r < roots.size(); ++r) {
                const CutRoot& root = roots[r];
                const auto where = [&] {
                    return "L_" + std::to_string(level) + "[" + std::to_string(r) +
                           "] = " + hex(root.code);
                };
                if (!morton::isValid(root.code) || morton::level(root.code) != level) {
                    return fail("1.2: " + where() + " is not a code of level " +
                                std::to_string(level));
                }
                if (r > 0 && roots[r - 1].code >= root.code) {
                    return fail("1.4: " + where() + " does not follow " + hex(roots[r - 1].code));
                }
                if (level >= 1 &&
                    morton::span(root.code >> 3, m_maxLevel) <= m_cut.fixedThrough(level)) {
                    return fail("1.5: " + where() + " has a parent with span <= " +
                                hex(m_cut.fixedThrough(level)) + " that fix did not create");
                }
                if (!checkRootEntry(level, root, where)) {
                    return false;
                }
            }
        }
        return true;
    }

    template <typename Where>
    bool checkRootEntry(int level, const CutRoot& root, const Where& where) {
        if (root.placeholder) {
            if (root.index >= m_cut.placeholderCount()) {
                return fail(where() + " names a placeholder that does not exist");
            }
            const Placeholder& placeholder = m_cut.placeholder(root.index);
            const int leafLevel = morton::level(placeholder.leafCode);
            if (leafLevel >= level || morton::span(placeholder.leafCode, level) != root.code) {
                return fail(where() + " is not the placeholder of leaf " +
                            hex(placeholder.leafCode));
            }
            if (m_hierarchy.findNode(placeholder.leafCode, m_hierarchy.nodeCount(leafLevel))) {
                return fail(where() + ": its leaf " + hex(placeholder.leafCode) +
                            " already exists (1.3)");
            }
            m_coverage.push_back({placeholder.coveredBegin, placeholder.coveredCount,
                                  morton::span(placeholder.leafCode, m_maxLevel)});
            return checkCoveredCodes(placeholder.leafCode, placeholder.coveredBegin,
                                     placeholder.coveredCount, where);
        }
        if (root.index >= m_hierarchy.nodeCount(level) ||
            m_hierarchy.node(level, root.index).code != root.code) {
            return fail(where() + " does not name a node of its level");
        }
        const OctreeNode& node = m_hierarchy.node(level, root.index);
        m_coverage.push_back(
            {node.coveredBegin, node.coveredCount, morton::span(node.code, m_maxLevel)});
        return true;
    }

    // Morton order: checking the first and last covered points checks all of them.
    template <typename Where>
    bool checkCoveredCodes(morton::Code code, std::uint64_t begin, std::uint64_t count,
                           const Where& where) {
        if (count == 0 || begin + count > m_context.insertedPoints) {
            return fail(where() + " covers [" + std::to_string(begin) + ", +" +
                        std::to_string(count) + "), outside the inserted input [0, " +
                        std::to_string(m_context.insertedPoints) + ")");
        }
        const int shift = 3 * (morton::kMaxLevel - morton::level(code));
        const SortedCloud& cloud = m_hierarchy.cloud();
        if ((cloud.code(begin) >> shift) != code ||
            (cloud.code(begin + count - 1) >> shift) != code) {
            return fail(where() + " covers input points outside its cell");
        }
        return true;
    }

    bool checkSubtrees() {
        std::vector<std::pair<int, std::size_t>> stack;
        for (int level = 0; level <= m_maxLevel; ++level) {
            for (const CutRoot& root : m_cut.roots(level)) {
                if (!root.placeholder) {
                    stack.emplace_back(level, root.index);
                }
            }
        }
        while (!stack.empty()) {
            const auto [level, index] = stack.back();
            stack.pop_back();
            if (m_visited[level][index]) {
                return fail("1.3: " + describe(level, index, m_hierarchy.node(level, index).code) +
                            " is in two subtrees");
            }
            m_visited[level][index] = true;
            if (!checkNode(level, index)) {
                return false;
            }
            const OctreeNode& node = m_hierarchy.node(level, index);
            for (std::uint32_t c = 0; c < node.childCount; ++c) {
                stack.emplace_back(level + 1, node.firstChild + c);
            }
        }
        for (int level = 0; level <= m_maxLevel; ++level) {
            const auto missing = std::find(m_visited[level].begin(), m_visited[level].end(), false);
            if (missing != m_visited[level].end()) {
                const auto index = static_cast<std::size_t>(missing - m_visited[level].begin());
                return fail("1.3: " + describe(level, index, m_hierarchy.node(level, index).code) +
                            " is in no subtree of the cut (lost)");
            }
        }
        return true;
    }

    bool checkNode(int level, std::size_t index) {
        const OctreeNode& node = m_hierarchy.node(level, index);
        const auto where = [&] {
            return describe(level, index, node.code);
        };
        if (!checkCoveredCodes(node.code, node.coveredBegin, node.coveredCount, where)) {
            return false;
        }
        if (node.isLeaf() != (node.childCount == 0)) {
            return fail(where() + ": the leaf flag disagrees with its child count");
        }
        if (node.splatScale != 1.0f) {
            return fail(where() + ": splat scale " + std::to_string(node.splatScale) +
                        "; a built node's splats are estimated from its own points (scale 1)");
        }
        if (node.isLeaf()) {
            return checkLeaf(level, node, where);
        }
        if (node.has(NodeFlag::Collapsed)) {
            return fail(where() + " is flagged collapsed but has children");
        }
        if (level == m_maxLevel || node.childCount > 8 ||
            node.firstChild + std::size_t{node.childCount} > m_hierarchy.nodeCount(level + 1)) {
            return fail(where() + " has children outside the next level");
        }
        std::array<const OctreeNode*, 8> childNodes{};
        const std::span<const OctreeNode* const> children(childNodes.data(), node.childCount);
        std::uint64_t nextCovered = node.coveredBegin;
        std::uint64_t childPoints = 0;
        for (std::uint32_t c = 0; c < node.childCount; ++c) {
            const OctreeNode& child = m_hierarchy.node(level + 1, node.firstChild + c);
            if ((child.code >> 3) != node.code) {
                return fail(where() + ": child " + hex(child.code) + " is not below it");
            }
            if (child.coveredBegin != nextCovered) {
                return fail(where() + ": the children's covered ranges do not tile its own");
            }
            nextCovered += child.coveredCount;
            childPoints += child.pointCount;
            childNodes[c] = &child;
        }
        if (nextCovered != std::uint64_t{node.coveredBegin} + node.coveredCount) {
            return fail(where() + ": its children cover " +
                        std::to_string(nextCovered - node.coveredBegin) + " points, it " +
                        std::to_string(node.coveredCount));
        }
        if (m_context.collapse != LeafCollapse::Off && node.childCount == 1 &&
            level + 1 == m_maxLevel && children[0]->isLeaf()) {
            return fail(where() + ": its only child is a leaf that collapse should have merged");
        }
        if (node.pointCount != sampleSize(childPoints, m_context.ratio)) {
            return fail(where() + " holds " + std::to_string(node.pointCount) +
                        " points; a sample of " +
                        std::to_string(sampleSize(childPoints, m_context.ratio)) + " of " +
                        std::to_string(childPoints) + " was expected");
        }
        // Samples ascend and are drawn from the children's held points (both lists ascend),
        // stored or implicit alike: an implicit sample whose children do not hold its covered
        // range would name points they do not hold.
        std::size_t child = 0;
        std::uint32_t held = 0;
        for (std::uint32_t s = 0; s < node.pointCount; ++s) {
            const std::uint32_t sample = node.heldPoint(s);
            if (s > 0 && sample <= node.heldPoint(s - 1)) {
                return fail(where() + ": samples not strictly ascending (duplicate?)");
            }
            while (child < children.size() && (held == children[child]->pointCount ||
                                               children[child]->heldPoint(held) < sample)) {
                if (held == children[child]->pointCount) {
                    ++child;
                    held = 0;
                } else {
                    ++held;
                }
            }
            if (child == children.size() || children[child]->heldPoint(held) != sample) {
                return fail(where() + ": sample " + std::to_string(sample) +
                            " is not a point of its children");
            }
        }
        return true;
    }

    template <typename Where>
    bool checkLeaf(int level, const OctreeNode& node, const Where& where) {
        if (!node.has(NodeFlag::Collapsed)) {
            if (level != m_maxLevel) {
                return fail(where() + " is a leaf above maxLevel without being collapsed");
            }
            if (!node.holdsRange() || node.pointCount != node.coveredCount) {
                return fail(where() + ": a leaf must hold all the points it covers");
            }
            return true;
        }
        if (m_context.collapse == LeafCollapse::Off || level != m_maxLevel - 1) {
            return fail(where() + " is collapsed, which this build does not do");
        }
        if (m_context.collapse == LeafCollapse::Lossless) {
            if (!node.holdsRange() || node.pointCount != node.coveredCount) {
                return fail(where() + ": a lossless collapsed leaf must hold all its points");
            }
            return true;
        }
        if (node.pointCount != sampleSize(node.coveredCount, m_context.ratio)) {
            return fail(where() + ": a paper-collapsed leaf must hold a sample of its points");
        }
        for (std::uint32_t s = 0; s < node.pointCount; ++s) {
            const std::uint32_t sample = node.heldPoint(s);
            if (sample < node.coveredBegin || sample >= node.coveredBegin + node.coveredCount ||
                (s > 0 && sample <= node.heldPoint(s - 1))) {
                return fail(where() + ": its sample is not an ascending subset of its points");
            }
        }
        return true;
    }

    bool checkTiling() {
        std::sort(m_coverage.begin(), m_coverage.end(),
                  [](const Coverage& a, const Coverage& b) { return a.begin < b.begin; });
        std::uint64_t next = 0;
        for (std::size_t i = 0; i < m_coverage.size(); ++i) {
            if (m_coverage[i].begin != next) {
                return fail("1.5: the cut's subtrees cover the input up to " +
                            std::to_string(next) + ", then resume at " +
                            std::to_string(m_coverage[i].begin) + " (points lost or doubled)");
            }
            if (i > 0 && m_coverage[i - 1].span >= m_coverage[i].span) {
                return fail("the cut's subtrees are not in span order along the input");
            }
            next += m_coverage[i].count;
        }
        if (next != m_context.insertedPoints) {
            return fail("1.5: the cut's subtrees cover " + std::to_string(next) + " of the " +
                        std::to_string(m_context.insertedPoints) + " inserted points");
        }
        return true;
    }

    const ObliqueCut& m_cut;
    const Hierarchy& m_hierarchy;
    const CutCheckContext& m_context;
    int m_maxLevel;
    std::vector<std::vector<bool>> m_visited;
    std::vector<Coverage> m_coverage;
    std::string m_error;
};

} // namespace

std::string checkCutInvariants(const ObliqueCut& cut, const Hierarchy& hierarchy,
                               const CutCheckContext& context) {
    return Checker(cut, hierarchy, context).run();
}

} // namespace omicron
