// The oblique cut on its own (codes only, no points): concatenate + fix, placeholders and
// interrupted passes, checked against a brute-force hierarchy after every step.
#include "build/oblique_cut.hpp"

#include <algorithm>
#include <gtest/gtest.h>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace omicron {
namespace {

// An adaptive octree given by its leaves (none an ancestor of another), and every node.
struct ReferenceTree {
    int maxLevel = 0;
    std::vector<morton::Code> leaves; // ascending by span
    std::set<morton::Code> leafSet;
    std::vector<std::set<morton::Code>> nodes; // per level
};

ReferenceTree referenceFromLeaves(int maxLevel, std::vector<morton::Code> leaves) {
    ReferenceTree tree;
    tree.maxLevel = maxLevel;
    std::sort(leaves.begin(), leaves.end(), [&](morton::Code a, morton::Code b) {
        return morton::span(a, maxLevel) < morton::span(b, maxLevel);
    });
    tree.leaves = leaves;
    tree.leafSet.insert(leaves.begin(), leaves.end());
    tree.nodes.resize(static_cast<std::size_t>(maxLevel) + 1);
    for (morton::Code leaf : leaves) {
        for (morton::Code c = leaf; c != 0; c >>= 3) {
            tree.nodes[morton::level(c)].insert(c);
        }
    }
    return tree;
}

// Random subdivision: each node is a leaf with probability leafChance (always at maxLevel),
// else has a random non-empty subset of children (each child with probability 3/8, so that
// deep trees stay a few thousand nodes).
void growLeaves(morton::Code node, int maxLevel, double leafChance, std::mt19937_64& random,
                std::vector<morton::Code>& leaves) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    if (morton::level(node) == maxLevel || unit(random) < leafChance) {
        leaves.push_back(node);
        return;
    }
    unsigned mask = 0;
    while (mask == 0) {
        for (unsigned c = 0; c < 8; ++c) {
            mask |= (random() % 8u < 3u ? 1u : 0u) << c;
        }
    }
    for (unsigned c = 0; c < 8; ++c) {
        if (mask & (1u << c)) {
            growLeaves(morton::child(node, c), maxLevel, leafChance, random, leaves);
        }
    }
}

// Records the nodes fix creates; a node's index is its position in its level's list.
class RecordingFactory : public ParentFactory {
public:
    RecordingFactory(const ObliqueCut& cut, int maxLevel)
        : m_cut(cut), created(static_cast<std::size_t>(maxLevel) + 1),
          children(static_cast<std::size_t>(maxLevel) + 1) {}

    CutRoot makeParent(int parentLevel, std::span<const CutRoot> siblings) override {
        EXPECT_FALSE(siblings.empty());
        if (siblings.front().placeholder) {
            EXPECT_EQ(siblings.size(), 1u) << "a placeholder shares its parent slot";
            const Placeholder& p = m_cut.placeholder(siblings.front().index);
            if (morton::level(p.leafCode) != parentLevel) {
                return {siblings.front().code >> 3, siblings.front().index, true};
            }
            ++substituted;
            return add(parentLevel, p.leafCode, {});
        }
        std::vector<morton::Code> kids;
        for (const CutRoot& s : siblings) {
            EXPECT_FALSE(s.placeholder);
            EXPECT_EQ(s.code >> 3, siblings.front().code >> 3);
            kids.push_back(s.code);
        }
        return add(parentLevel, siblings.front().code >> 3, kids);
    }

    CutRoot add(int level, morton::Code code, std::vector<morton::Code> kids) {
        EXPECT_TRUE(created[level].empty() || created[level].back() < code)
            << "nodes of a level must be created in Morton order";
        created[level].push_back(code);
        children[level].push_back(std::move(kids));
        return {code, static_cast<std::uint32_t>(created[level].size() - 1), false};
    }

    const ObliqueCut& m_cut;
    std::vector<std::vector<morton::Code>> created;
    std::vector<std::vector<std::vector<morton::Code>>> children;
    int substituted = 0;
};

// Concatenates the leaves of `tree` (placeholders for shallow ones) in batches.
CutRoot concatenateLeaf(ObliqueCut& cut, RecordingFactory& factory, morton::Code leaf) {
    const int maxLevel = cut.maxLevel();
    if (morton::level(leaf) == maxLevel) {
        return factory.add(maxLevel, leaf, {});
    }
    const std::uint32_t id = cut.addPlaceholder({leaf, 0, 1});
    return {morton::span(leaf, maxLevel), id, true};
}

// The state after level steps: level l holds exactly the reference nodes whose span is within
// what the level below was fixed through; every root's parent is beyond that.
void expectCutMatches(const ObliqueCut& cut, const RecordingFactory& factory,
                      const ReferenceTree& tree, const std::string& when) {
    SCOPED_TRACE(when);
    const int maxLevel = tree.maxLevel;
    for (int level = 0; level <= maxLevel; ++level) {
        const morton::Code limit =
            level == maxLevel ? cut.delimiter() : cut.fixedThrough(level + 1);
        std::vector<morton::Code> expected;
        for (morton::Code code : tree.nodes[level]) {
            const bool isLeaf = tree.leafSet.count(code) != 0;
            // maxLevel nodes exist once concatenated; others once the level below was fixed.
            if (level == maxLevel ? (isLeaf && code <= limit)
                                  : (limit != 0 && morton::span(code, maxLevel) <= limit)) {
                expected.push_back(code);
            }
        }
        ASSERT_EQ(factory.created[level], expected) << "nodes of level " << level;

        const auto roots = cut.roots(level);
        for (std::size_t r = 0; r < roots.size(); ++r) {
            ASSERT_EQ(morton::level(roots[r].code), level) << "1.2";
            if (r > 0) {
                ASSERT_LT(roots[r - 1].code, roots[r].code) << "1.4";
            }
            if (level >= 1) {
                ASSERT_GT(morton::span(roots[r].code >> 3, maxLevel), cut.fixedThrough(level))
                    << "1.5: a root whose parent fix should have created";
            }
        }
    }
    // 1.3 and completeness: every created node is reached exactly once from the roots.
    std::map<morton::Code, int> reached;
    std::vector<std::pair<int, std::uint32_t>> stack;
    for (int level = 0; level <= maxLevel; ++level) {
        for (const CutRoot& root : cut.roots(level)) {
            if (!root.placeholder) {
                stack.emplace_back(level, root.index);
            }
        }
    }
    while (!stack.empty()) {
        const auto [level, index] = stack.back();
        stack.pop_back();
        ++reached[factory.created[level][index]];
        for (morton::Code kid : factory.children[level][index]) {
            const auto& next = factory.created[level + 1];
            const auto at = std::lower_bound(next.begin(), next.end(), kid);
            ASSERT_TRUE(at != next.end() && *at == kid);
            stack.emplace_back(level + 1, static_cast<std::uint32_t>(at - next.begin()));
        }
    }
    std::size_t total = 0;
    for (const auto& level : factory.created) {
        total += level.size();
    }
    ASSERT_EQ(reached.size(), total) << "a created node is in no subtree";
    for (const auto& [code, times] : reached) {
        ASSERT_EQ(times, 1) << "1.3: node " << code << " is in " << times << " subtrees";
    }
}

void expectFinished(const ObliqueCut& cut, const RecordingFactory& factory,
                    const ReferenceTree& tree) {
    for (int level = 0; level <= tree.maxLevel; ++level) {
        const std::vector<morton::Code> expected(tree.nodes[level].begin(),
                                                 tree.nodes[level].end());
        EXPECT_EQ(factory.created[level], expected) << "level " << level;
        EXPECT_EQ(cut.roots(level).size(), level == 0 ? 1u : 0u)
            << "the finished cut is one subtree: the hierarchy";
    }
    ASSERT_EQ(cut.roots(0).size(), 1u);
    EXPECT_EQ(cut.roots(0).front().code, morton::kRoot);
}

// Runs concatenate + fix over `tree` in random batches; `interruptChance` stops passes part
// way up (multipass), as the builder does when new input arrives.
void runCut(const ReferenceTree& tree, std::uint64_t seed, double interruptChance) {
    std::mt19937_64 random(seed);
    ObliqueCut cut(tree.maxLevel);
    RecordingFactory factory(cut, tree.maxLevel);
    std::vector<CutRoot> parents;
    const auto levelStep = [&](int level) {
        parents.clear();
        forEachSiblingGroup(cut.pendingRoots(level), [&](std::span<const CutRoot> siblings) {
            parents.push_back(factory.makeParent(level - 1, siblings));
        });
        cut.completeLevel(level, parents);
    };
    std::size_t next = 0;
    int step = 0;
    while (next < tree.leaves.size()) {
        const std::size_t batch = 1 + random() % 7;
        std::vector<CutRoot> leaves;
        for (; next < tree.leaves.size() && leaves.size() < batch; ++next) {
            leaves.push_back(concatenateLeaf(cut, factory, tree.leaves[next]));
        }
        cut.concatenate(leaves);
        ASSERT_EQ(cut.delimiter(), leaves.back().code) << "1.1: m_C is the last leaf";
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        if (unit(random) < interruptChance) {
            const int stopAt = 1 + static_cast<int>(random() % tree.maxLevel);
            for (int level = tree.maxLevel; level >= stopAt; --level) {
                levelStep(level);
            }
        } else {
            fix(cut, factory);
            for (int level = 1; level <= tree.maxLevel; ++level) {
                ASSERT_EQ(cut.fixedThrough(level), cut.delimiter());
            }
        }
        expectCutMatches(cut, factory, tree, "step " + std::to_string(step++));
        if (testing::Test::HasFatalFailure()) {
            return;
        }
    }
    cut.close();
    fix(cut, factory);
    expectCutMatches(cut, factory, tree, "after close");
    expectFinished(cut, factory, tree);
}

TEST(ObliqueCut, EmptyCutHasNoDelimiterAndNothingPending) {
    ObliqueCut cut(4);
    EXPECT_FALSE(cut.hasDelimiter());
    for (int level = 1; level <= 4; ++level) {
        EXPECT_TRUE(cut.pendingRoots(level).empty());
    }
    cut.close();
    EXPECT_EQ(cut.delimiter(), morton::span(morton::kRoot, 4));
}

TEST(ObliqueCut, SingleLeafBecomesAChainUpToTheRoot) {
    const int maxLevel = 5;
    const morton::Code leaf = morton::encode({3, 17, 9}, maxLevel);
    runCut(referenceFromLeaves(maxLevel, {leaf}), 1, 0.0);
}

TEST(ObliqueCut, ConcatenateKeepsEveryInvariantButFixOnlyCreatesQualifyingParents) {
    // Leaves 0..7 of one parent, then a leaf of the next parent: after the first eight, the
    // parent's span equals m_C and fix must create it; its own parent must wait.
    const int maxLevel = 2;
    std::vector<morton::Code> leaves;
    for (unsigned c = 0; c < 8; ++c) {
        leaves.push_back(morton::child(0b1000, c));
    }
    leaves.push_back(morton::child(0b1001, 0));
    const ReferenceTree tree = referenceFromLeaves(maxLevel, leaves);
    ObliqueCut cut(maxLevel);
    RecordingFactory factory(cut, maxLevel);
    std::vector<CutRoot> roots;
    for (std::size_t i = 0; i < 8; ++i) {
        roots.push_back(concatenateLeaf(cut, factory, leaves[i]));
    }
    cut.concatenate(roots);
    EXPECT_EQ(cut.pendingRoots(2).size(), 8u);
    fix(cut, factory);
    EXPECT_EQ(factory.created[1], std::vector<morton::Code>{0b1000});
    EXPECT_TRUE(factory.created[0].empty());
    ASSERT_EQ(cut.roots(1).size(), 1u);
    expectCutMatches(cut, factory, tree, "first parent");
}

TEST(ObliqueCut, RandomHierarchiesMatchTheReferenceAfterEveryFix) {
    for (int maxLevel = 1; maxLevel <= 6; ++maxLevel) {
        for (std::uint64_t seed = 0; seed < 12; ++seed) {
            SCOPED_TRACE("maxLevel " + std::to_string(maxLevel) + " seed " + std::to_string(seed));
            std::mt19937_64 random(seed * 31 + static_cast<std::uint64_t>(maxLevel));
            std::vector<morton::Code> leaves;
            growLeaves(morton::kRoot, maxLevel, 0.0, random, leaves);
            runCut(referenceFromLeaves(maxLevel, leaves), seed, 0.0);
            if (HasFatalFailure()) {
                return;
            }
        }
    }
}

TEST(ObliqueCut, PlaceholdersCarryShallowLeavesToTheirLevel) {
    for (int maxLevel = 1; maxLevel <= 6; ++maxLevel) {
        for (std::uint64_t seed = 0; seed < 12; ++seed) {
            SCOPED_TRACE("maxLevel " + std::to_string(maxLevel) + " seed " + std::to_string(seed));
            std::mt19937_64 random(seed * 17 + static_cast<std::uint64_t>(maxLevel));
            std::vector<morton::Code> leaves;
            growLeaves(morton::kRoot, maxLevel, 0.3, random, leaves);
            runCut(referenceFromLeaves(maxLevel, leaves), seed, 0.0);
            if (HasFatalFailure()) {
                return;
            }
        }
    }
}

TEST(ObliqueCut, InterruptedPassesResumeFromMaxLevel) {
    for (int maxLevel = 2; maxLevel <= 6; ++maxLevel) {
        for (std::uint64_t seed = 0; seed < 12; ++seed) {
            SCOPED_TRACE("maxLevel " + std::to_string(maxLevel) + " seed " + std::to_string(seed));
            std::mt19937_64 random(seed * 7 + static_cast<std::uint64_t>(maxLevel));
            std::vector<morton::Code> leaves;
            growLeaves(morton::kRoot, maxLevel, 0.15, random, leaves);
            runCut(referenceFromLeaves(maxLevel, leaves), seed, 0.6);
            if (HasFatalFailure()) {
                return;
            }
        }
    }
}

TEST(ObliqueCut, AdversarialLeafSets) {
    const int maxLevel = 3;
    const morton::Code last = morton::span(morton::kRoot, maxLevel);
    const morton::Code first = morton::encode({0, 0, 0}, maxLevel);
    std::vector<morton::Code> dense;
    for (morton::Code c = first; c <= last; ++c) {
        dense.push_back(c);
    }
    const std::vector<std::pair<const char*, std::vector<morton::Code>>> cases = {
        {"the max corner only (its code is span(root))", {last}},
        {"the min corner only", {first}},
        {"two distant corners", {first, last}},
        {"every cell", dense},
        {"the root itself is a leaf", {morton::kRoot}},
        {"one shallow leaf and one deep", {morton::encode({0, 0, 0}, 1), last}},
    };
    for (const auto& [name, leaves] : cases) {
        SCOPED_TRACE(name);
        runCut(referenceFromLeaves(maxLevel, leaves), 5, 0.3);
        if (HasFatalFailure()) {
            return;
        }
    }
}

TEST(ObliqueCut, DeepestLevelUsesAllSixtyFourBits) {
    const int maxLevel = morton::kMaxLevel;
    const std::vector<morton::Code> leaves = {
        morton::encode({0, 0, 0}, maxLevel), morton::encode({5, 1, 2}, maxLevel),
        morton::encode(
            {morton::kCellsPerAxis - 1, morton::kCellsPerAxis - 1, morton::kCellsPerAxis - 1},
            maxLevel)};
    runCut(referenceFromLeaves(maxLevel, leaves), 3, 0.5);
}

} // namespace
} // namespace omicron
