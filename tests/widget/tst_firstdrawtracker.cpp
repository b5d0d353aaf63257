// FirstDrawTracker (no GL): over a real build's insertion log, a leaf counts as drawn once a
// drawn range covers it (its own node or an ancestor), exactly once, and leaves published
// before the attach are not measured.
#include "build/hierarchy.hpp"
#include "first_draw_tracker.hpp"
#include "pipeline/build_pipeline.hpp"

#include <QtTest>
#include <vector>

using namespace omicron;

namespace {

std::shared_ptr<const Hierarchy> builtScene(FirstDrawTracker::Clock::time_point* before) {
    BuildPipeline pipeline; // the hierarchy outlives it (shared)
    PipelineOptions options;
    options.build.maxLevel = 6;
    *before = FirstDrawTracker::Clock::now();
    pipeline.runGeneratedScene(40'000, 3, options);
    return pipeline.hierarchy();
}

std::vector<FirstDrawTracker::CoveredRange> rangesOf(const Hierarchy& hierarchy, int level) {
    std::vector<FirstDrawTracker::CoveredRange> ranges;
    for (std::size_t i = 0; i < hierarchy.nodeCount(level); ++i) {
        const OctreeNode& node = hierarchy.node(level, i);
        ranges.push_back({node.coveredBegin, node.coveredCount});
    }
    return ranges;
}

} // namespace

class tst_FirstDrawTracker : public QObject {
    Q_OBJECT
private slots:
    void everyLeafIsCountedOnceWhenANodeCoveringItIsDrawn() {
        FirstDrawTracker::Clock::time_point before;
        const auto hierarchy = builtScene(&before);
        QVERIFY(hierarchy != nullptr);
        const std::size_t leaves = hierarchy->insertionCount();
        QVERIFY(leaves > 100);
        FirstDrawTracker tracker;
        tracker.reset(before); // attached before the build began: every leaf is measured

        // Level 2 drawn except its first and last nodes: the leaves under the others.
        std::vector<FirstDrawTracker::CoveredRange> level2 = rangesOf(*hierarchy, 2);
        QVERIFY(level2.size() >= 3);
        const std::vector<FirstDrawTracker::CoveredRange> middle(level2.begin() + 1,
                                                                 level2.end() - 1);
        const auto now = FirstDrawTracker::Clock::now();
        tracker.markDrawn(*hierarchy, middle, now);
        const auto underMiddle = [&](const CutInsertion& leaf) {
            return leaf.coveredBegin >= middle.front().begin &&
                   leaf.coveredBegin < middle.back().begin + middle.back().count;
        };
        std::size_t leavesUnderMiddle = 0;
        for (std::size_t i = 0; i < leaves; ++i) {
            leavesUnderMiddle += underMiddle(hierarchy->insertion(i)) ? 1 : 0;
        }
        QVERIFY(leavesUnderMiddle > 0);
        FirstDrawTracker::Delays delays = tracker.take();
        QCOMPARE(delays.leaves, leavesUnderMiddle);
        QCOMPARE(tracker.leavesWaiting(), leaves - leavesUnderMiddle);
        QVERIFY(delays.medianMs >= 0.0);
        QVERIFY(delays.medianMs <= delays.maxMs);
        // The oldest leaf of the frame sets the maximum: its publication to `now`.
        double oldest = 0.0;
        for (std::size_t i = 0; i < leaves; ++i) {
            const CutInsertion& leaf = hierarchy->insertion(i);
            if (underMiddle(leaf)) {
                oldest = std::max(
                    oldest,
                    std::chrono::duration<double, std::milli>(now - leaf.publishedAt).count());
            }
        }
        QCOMPARE(delays.maxMs, oldest);

        // Drawn again: nothing new. The root covers the rest.
        tracker.markDrawn(*hierarchy, middle, FirstDrawTracker::Clock::now());
        QCOMPARE(tracker.take().leaves, std::size_t{0});
        tracker.markDrawn(*hierarchy, rangesOf(*hierarchy, 0), FirstDrawTracker::Clock::now());
        QCOMPARE(tracker.take().leaves, leaves - leavesUnderMiddle);
        QCOMPARE(tracker.leavesWaiting(), std::size_t{0});
        // The leaves themselves, drawn after their ancestors: not first draws.
        tracker.markDrawn(*hierarchy, rangesOf(*hierarchy, hierarchy->maxLevel()),
                          FirstDrawTracker::Clock::now());
        QCOMPARE(tracker.take().leaves, std::size_t{0});
    }

    void leavesPublishedBeforeTheAttachAreNotMeasured() {
        FirstDrawTracker::Clock::time_point before;
        const auto hierarchy = builtScene(&before);
        FirstDrawTracker tracker;
        tracker.reset(FirstDrawTracker::Clock::now()); // attached to a finished build
        tracker.markDrawn(*hierarchy, rangesOf(*hierarchy, 0), FirstDrawTracker::Clock::now());
        QCOMPARE(tracker.take().leaves, std::size_t{0});
        QCOMPARE(tracker.leavesWaiting(), std::size_t{0});
    }
};

QTEST_MAIN(tst_FirstDrawTracker)
#include "tst_firstdrawtracker.moc"
