// The invariant checker itself: silent on a valid cut, and naming the broken invariant on
// hand-made corrupt ones (a checker that never fails proves nothing).
#include "build/cut_invariants.hpp"
#include "build/parent_sampler.hpp"

#include <algorithm>
#include <functional>
#include <gtest/gtest.h>
#include <memory>
#include <vector>

namespace omicron {
namespace {

constexpr int kMaxLevel = 2;

// Four points in four level-2 cells: two siblings, then two cells of other parents.
std::shared_ptr<SortedCloud> fourPointCloud() {
    std::vector<glm::vec3> positions = {
        {0.1f, 0.1f, 0.1f}, {0.3f, 0.1f, 0.1f}, {0.6f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}};
    auto cloud = std::make_shared<SortedCloud>(CubeTransform{}, glm::dvec3(0.0), AttributeSet{},
                                               positions.size());
    std::vector<std::pair<morton::Code, glm::vec3>> sorted;
    for (const glm::vec3& p : positions) {
        sorted.emplace_back(morton::encodeUnit(p.x, p.y, p.z), p);
    }
    std::sort(sorted.begin(), sorted.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        cloud->mutablePositions()[i] = sorted[i].second;
    }
    cloud->publish(sorted.size());
    cloud->markComplete();
    return cloud;
}

// Makes parents the way the builder does, with a hook to corrupt them.
class TestFactory : public ParentFactory {
public:
    TestFactory(Hierarchy& hierarchy, double ratio) : m_hierarchy(hierarchy), m_ratio(ratio) {}

    std::function<void(OctreeNode&, SampleBuffer&)> corrupt;

    CutRoot makeParent(int parentLevel, std::span<const CutRoot> siblings) override {
        std::vector<const OctreeNode*> children;
        OctreeNode parent;
        parent.code = siblings.front().code >> 3;
        parent.firstChild = siblings.front().index;
        parent.childCount = static_cast<std::uint8_t>(siblings.size());
        std::uint64_t childPoints = 0;
        for (const CutRoot& s : siblings) {
            children.push_back(&m_hierarchy.node(parentLevel + 1, s.index));
            parent.coveredCount += children.back()->coveredCount;
            childPoints += children.back()->pointCount;
        }
        parent.coveredBegin = children.front()->coveredBegin;
        parent.pointCount = sampleSize(childPoints, m_ratio);
        SampleBuffer samples(parent.pointCount);
        sampleChildren(children, samples);
        if (corrupt) {
            corrupt(parent, samples);
        }
        parent.sampleIndices = m_hierarchy.adoptSamples(std::move(samples));
        const std::size_t index = m_hierarchy.appendNode(parentLevel, parent);
        m_hierarchy.publishNodes(parentLevel);
        return {parent.code, static_cast<std::uint32_t>(index), false};
    }

private:
    Hierarchy& m_hierarchy;
    double m_ratio;
};

struct Fixture {
    std::shared_ptr<SortedCloud> cloud = fourPointCloud();
    Hierarchy hierarchy{cloud, kMaxLevel};
    ObliqueCut cut{kMaxLevel};
    CutCheckContext context;

    Fixture() {
        context.ratio = 1.0;
        context.insertedPoints = 4;
        std::vector<CutRoot> leaves;
        for (std::uint32_t i = 0; i < 4; ++i) {
            OctreeNode leaf;
            leaf.code = morton::codeAtLevel(cloud->code(i), kMaxLevel);
            leaf.coveredBegin = i;
            leaf.coveredCount = 1;
            leaf.pointCount = 1;
            leaf.flags = static_cast<std::uint8_t>(NodeFlag::Leaf);
            leaves.push_back({leaf.code,
                              static_cast<std::uint32_t>(hierarchy.appendNode(kMaxLevel, leaf)),
                              false});
        }
        hierarchy.publishNodes(kMaxLevel);
        cut.concatenate(leaves);
    }

    std::string check() { return checkCutInvariants(cut, hierarchy, context); }
};

TEST(CutInvariants, ValidCutAfterConcatenateAndAfterFix) {
    Fixture f;
    EXPECT_EQ(f.check(), "") << "concatenate leaves the per-level invariants intact";
    f.context.requireCompleteFix = true;
    EXPECT_NE(f.check().find("fix incomplete"), std::string::npos) << f.check();
    TestFactory factory(f.hierarchy, f.context.ratio);
    fix(f.cut, factory);
    EXPECT_EQ(f.check(), "");
    f.cut.close();
    fix(f.cut, factory);
    EXPECT_EQ(f.check(), "");
    EXPECT_EQ(f.hierarchy.nodeCount(0), 1u);
}

TEST(CutInvariants, MissingInputIsReported) {
    Fixture f;
    f.context.insertedPoints = 5;
    EXPECT_NE(f.check().find("1.5: the cut's subtrees cover 4 of the 5"), std::string::npos)
        << f.check();
}

TEST(CutInvariants, LostNodeIsReported) {
    Fixture f;
    OctreeNode stray;
    stray.code = 0b1010; // a level-1 node that no fix made: in no subtree
    stray.flags = static_cast<std::uint8_t>(NodeFlag::Leaf);
    f.hierarchy.appendNode(1, stray);
    f.hierarchy.publishNodes(1);
    EXPECT_NE(f.check().find("is in no subtree of the cut (lost)"), std::string::npos) << f.check();
}

TEST(CutInvariants, DroppedRootsAreReported) {
    Fixture f;
    f.cut.close();
    f.cut.completeLevel(kMaxLevel, {}); // a fix that forgot to make the parents
    EXPECT_NE(f.check().find("1.3"), std::string::npos) << f.check();
}

struct Corruption {
    const char* name;
    std::function<void(OctreeNode&, SampleBuffer&)> corrupt;
    const char* expected;
    double ratio = 1.0;
};

TEST(CutInvariants, CorruptParentsAreReported) {
    const Corruption cases[] = {
        {"duplicate sample",
         [](OctreeNode&, SampleBuffer& s) {
             if (s.size() == 2) {
                 s[1] = s[0];
             }
         },
         "samples not strictly ascending"},
        // Ratio 0.5: the level-1 parent of points 0 and 1 keeps only point 1, so the root's
        // sample [1, 3] must not take point 0.
        {"sample from elsewhere",
         [](OctreeNode& n, SampleBuffer& s) {
             if (n.code == morton::kRoot) {
                 s.front() = 0;
             }
         },
         "sample 0 is not a point of its children", 0.5},
        {"wrong sample size",
         [](OctreeNode& n, SampleBuffer& s) {
             s.push_back(s.back());
             n.pointCount = static_cast<std::uint32_t>(s.size());
         },
         "was expected"},
        {"child lost by a merge",
         [](OctreeNode& n, SampleBuffer&) {
             if (n.childCount == 2) {
                 n.childCount = 1;
             }
         },
         "its children cover"},
        {"splat scale", [](OctreeNode& n, SampleBuffer&) { n.splatScale *= 2.0f; },
         "splat scale"},
        {"flagged collapsed",
         [](OctreeNode& n, SampleBuffer&) {
             n.flags = static_cast<std::uint8_t>(NodeFlag::Collapsed);
         },
         "flagged collapsed but has children"},
    };
    for (const Corruption& c : cases) {
        SCOPED_TRACE(c.name);
        Fixture f;
        f.context.ratio = c.ratio;
        TestFactory factory(f.hierarchy, f.context.ratio);
        factory.corrupt = c.corrupt;
        f.cut.close();
        fix(f.cut, factory);
        const std::string error = f.check();
        EXPECT_NE(error.find(c.expected), std::string::npos) << error;
    }
}

} // namespace
} // namespace omicron
