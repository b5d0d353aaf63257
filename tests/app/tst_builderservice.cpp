// BuilderService: opens real files through the entry File -> Open uses, reports monotonic
// progress at <= 10 Hz, rebuilds without reading again, exports what loads back identically,
// reports bad files by name, and stops promptly on cancel and destruction.
#include "app_test_support.hpp"
#include "builder_service.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "scene/scene_generator.hpp"

#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QtTest>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>

using namespace omicron;

namespace {

constexpr int kBuildTimeoutMs = 120'000;

// An ascii PLY of 150,000 generated points, about 10 MB: ten blocks of bounds scanning.
QString writeAsciiScan(const QTemporaryDir& dir) {
    const QString path = dir.filePath(QStringLiteral("scan.ply"));
    PlyWriteOptions ascii;
    ascii.encoding = PlyEncoding::Ascii;
    const GeneratedScene scene = generateScene(150'000, 3);
    writePly(path.toStdString(), scene.points, scene.cube, ascii);
    return path;
}

PipelineOptions testOptions(int depth = 6) {
    PipelineOptions options;
    options.build.maxLevel = depth;
    options.build.checkInvariants = true;
    options.sortChunks = 8;
    return options;
}

PipelineResult waitForBuild(QSignalSpy& finished, QSignalSpy& failed) {
    [&] {
        QTRY_VERIFY_WITH_TIMEOUT(finished.count() + failed.count() > 0, kBuildTimeoutMs);
    }();
    if (failed.count() > 0) {
        qWarning() << "build failed:" << failed.first();
        return {};
    }
    return finished.takeFirst().at(0).value<PipelineResult>();
}

void expectSameLevels(const BuildStatistics& a, const BuildStatistics& b) {
    QCOMPARE(a.levels.size(), b.levels.size());
    for (std::size_t level = 0; level < a.levels.size(); ++level) {
        QCOMPARE(a.levels[level].nodes, b.levels[level].nodes);
        QCOMPARE(a.levels[level].points, b.levels[level].points);
    }
}

} // namespace

class TestBuilderService : public QObject {
    Q_OBJECT
private slots:
    void openSharedFileReportsMonotonicThrottledProgress();
    void rebuildReusesTheSortedDataWithoutReading();
    void malformedFileIsReportedByNameAndTheHierarchyIsKept();
    void exportsLoadBackIdentically();
    void savedHierarchyLoadsBackWithIdenticalStatistics();
    void potreeExportStoresEveryPointOnceAndCancelLeavesNothing();
    void cancelMidBuildEndsTheRun();
    void cancelDuringTheBoundsPrePassKeepsThePreviousCloud();
    void firstPixelsComeFromTheBoundsPrePass();
    void destroyingMidBuildJoinsEveryThread();
    void newOpenWhileBusyReplacesTheRunningBuild();
};

void TestBuilderService::openSharedFileReportsMonotonicThrottledProgress() {
    OMICRON_REQUIRE_SHARED_FILE(path, "autzen_trim.las");
    BuilderService service;
    service.setOptions(testOptions(7));
    QSignalSpy started(&service, &BuilderService::buildStarted);
    QSignalSpy progress(&service, &BuilderService::progressChanged);
    QSignalSpy statistics(&service, &BuilderService::statisticsChanged);
    QSignalSpy hierarchy(&service, &BuilderService::hierarchyChanged);
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QElapsedTimer clock;
    clock.start();
    service.open(path);
    QVERIFY(service.busy());
    QCOMPARE(started.count(), 1);
    QCOMPARE(started.first().at(0).toString(), QStringLiteral("autzen_trim.las"));
    const PipelineResult result = waitForBuild(finished, failed);
    const double seconds = clock.elapsed() / 1000.0;
    QVERIFY(result.stats.complete);
    QVERIFY2(result.stats.invariantViolation.empty(), result.stats.invariantViolation.c_str());
    QCOMPARE(result.source.kind, PipelineKind::UnsortedCloud);
    QTRY_VERIFY(!service.busy());
    QVERIFY(hierarchy.count() >= 1);
    QVERIFY(statistics.count() >= 1);
    QVERIFY(progress.count() >= 1);
    // <= 10 Hz: one per 100 ms tick, plus the final poll when the worker returns.
    QVERIFY2(progress.count() <= seconds * 10.0 + 2.0,
             qPrintable(
                 QStringLiteral("%1 progress signals in %2 s").arg(progress.count()).arg(seconds)));
    PipelineProgress previous;
    for (const QList<QVariant>& signal : progress) {
        const auto p = signal.at(0).value<PipelineProgress>();
        QVERIFY(static_cast<int>(p.phase) >= static_cast<int>(previous.phase));
        QVERIFY(p.pointsRead >= previous.pointsRead);
        QVERIFY(p.pointsSorted >= previous.pointsSorted);
        QVERIFY(p.pointsInserted >= previous.pointsInserted);
        QVERIFY(p.cutDelimiter >= previous.cutDelimiter);
        previous = p;
    }
    QCOMPARE(previous.phase, BuildPhase::Complete);
    QCOMPARE(previous.pointsInserted, result.source.pointCount);
    QCOMPARE(service.sourceReads(), 1u);
}

void TestBuilderService::rebuildReusesTheSortedDataWithoutReading() {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    BuilderService service;
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    service.open(path);
    const PipelineResult first = waitForBuild(finished, failed);
    QVERIFY(first.stats.complete);
    QTRY_VERIFY(!service.busy());
    QCOMPARE(service.sourceReads(), 1u);
    const auto firstHierarchy = service.hierarchy();

    BuildOptions deeper = testOptions(9).build;
    deeper.collapse = LeafCollapse::Paper;
    deeper.ratio = 0.25;
    QVERIFY(service.rebuild(deeper));
    const PipelineResult second = waitForBuild(finished, failed);
    QVERIFY(second.stats.complete);
    QCOMPARE(service.sourceReads(), 1u); // no re-read, no re-sort
    QVERIFY(service.hierarchy() != firstHierarchy);
    QCOMPARE(service.hierarchy()->maxLevel(), 9);
    QCOMPARE(second.stats.levels.size(), std::size_t{10});
    QVERIFY(second.stats.droppedPoints > 0); // the paper's collapse did act
}

void TestBuilderService::malformedFileIsReportedByNameAndTheHierarchyIsKept() {
    QTemporaryDir dir;
    BuilderService service;
    service.setOptions(testOptions(5));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    service.openGeneratedScene(20'000, 2);
    QVERIFY(waitForBuild(finished, failed).stats.complete);
    QTRY_VERIFY(!service.busy());
    const auto kept = service.hierarchy();

    const QString bad = dir.filePath(QStringLiteral("broken.las"));
    QFile file(bad);
    QVERIFY(file.open(QIODevice::WriteOnly));
    file.write("LASF this is not a LAS header");
    file.close();
    service.open(bad);
    QTRY_VERIFY_WITH_TIMEOUT(failed.count() == 1, kBuildTimeoutMs);
    QCOMPARE(failed.first().at(0).toString(), bad);
    QVERIFY2(failed.first().at(1).toString().contains(bad),
             qPrintable(failed.first().at(1).toString()));
    QTRY_VERIFY(!service.busy());
    QCOMPARE(service.hierarchy(), kept);
    QCOMPARE(finished.count(), 0);
    // Still usable: the kept cloud rebuilds.
    failed.clear();
    QVERIFY(service.rebuild(testOptions(6).build));
    QVERIFY(waitForBuild(finished, failed).stats.complete);
}

void TestBuilderService::exportsLoadBackIdentically() {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    QTemporaryDir dir;
    BuilderService service;
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy jobs(&service, &BuilderService::jobFinished);
    service.open(path);
    const PipelineResult original = waitForBuild(finished, failed);
    QTRY_VERIFY(!service.busy());

    const QString oms = dir.filePath(QStringLiteral("bunny.oms"));
    QVERIFY(service.exportSortedStream(oms));
    QTRY_VERIFY_WITH_TIMEOUT(jobs.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!service.busy());
    const QString las = dir.filePath(QStringLiteral("bunny.las"));
    QVERIFY(service.exportPoints(las));
    QTRY_VERIFY_WITH_TIMEOUT(jobs.count() == 2, kBuildTimeoutMs);
    QTRY_VERIFY(!service.busy());
    QCOMPARE(failed.count(), 0);
    QCOMPARE(loadPointCloud(las.toStdString()).points.size(), original.source.pointCount);

    // Pipeline 2 from the exported stream: the same hierarchy.
    service.open(oms);
    const PipelineResult reloaded = waitForBuild(finished, failed);
    QCOMPARE(reloaded.source.kind, PipelineKind::SortedStream);
    expectSameLevels(original.stats, reloaded.stats);

    // A bad target names the file.
    QTRY_VERIFY(!service.busy());
    const QString badTarget = dir.filePath(QStringLiteral("points.txt"));
    QVERIFY(service.exportPoints(badTarget));
    QTRY_VERIFY_WITH_TIMEOUT(failed.count() == 1, kBuildTimeoutMs);
    QVERIFY(failed.first().at(1).toString().contains(badTarget));
}

// Save Hierarchy As (.omh) then File > Open of that file: pipeline 3 gives the same counts.
void TestBuilderService::savedHierarchyLoadsBackWithIdenticalStatistics() {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    QTemporaryDir dir;
    BuilderService service;
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy jobs(&service, &BuilderService::jobFinished);
    QSignalSpy hierarchies(&service, &BuilderService::hierarchyChanged);
    service.open(path);
    const PipelineResult original = waitForBuild(finished, failed);
    QTRY_VERIFY(!service.busy());

    const QString omh = dir.filePath(QStringLiteral("bunny.omh"));
    QVERIFY(service.saveHierarchy(omh));
    QTRY_VERIFY_WITH_TIMEOUT(jobs.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!service.busy());
    QCOMPARE(failed.count(), 0);
    QVERIFY(QFileInfo(omh).size() > 0);

    hierarchies.clear();
    service.openHierarchy(omh);
    const PipelineResult loaded = waitForBuild(finished, failed);
    QCOMPARE(loaded.source.kind, PipelineKind::HierarchyFile);
    QVERIFY(loaded.stats.complete);
    QCOMPARE(loaded.stats.inputPoints, original.stats.inputPoints);
    expectSameLevels(original.stats, loaded.stats);
    QTRY_VERIFY(hierarchies.count() > 0); // the view gets the loaded hierarchy
    const auto hierarchy = hierarchies.last().at(0).value<std::shared_ptr<const Hierarchy>>();
    QVERIFY(hierarchy != nullptr);
    for (int level = 0; level <= hierarchy->maxLevel(); ++level) {
        QCOMPARE(hierarchy->nodeCount(level), original.stats.levels[level].nodes);
    }

    // A damaged file is reported by name; the loaded hierarchy stays.
    QTRY_VERIFY(!service.busy());
    const QString damaged = dir.filePath(QStringLiteral("damaged.omh"));
    QVERIFY(QFile::copy(omh, damaged));
    QVERIFY(QFile::resize(damaged, QFileInfo(damaged).size() / 2));
    service.openHierarchy(damaged);
    QTRY_VERIFY_WITH_TIMEOUT(failed.count() == 1, kBuildTimeoutMs);
    QVERIFY(failed.first().at(1).toString().contains(QStringLiteral("damaged.omh")));
}

// File > Export Potree: off the GUI thread with progress; every point once; Cancel mid-way
// leaves neither the folder nor a temporary one; asked too early, it is refused by name.
void TestBuilderService::potreeExportStoresEveryPointOnceAndCancelLeavesNothing() {
    QTemporaryDir dir;
    BuilderService service;
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy jobs(&service, &BuilderService::jobFinished);
    QSignalSpy progress(&service, &BuilderService::jobProgressChanged);
    const QString folder = dir.filePath(QStringLiteral("potree"));
    QVERIFY(!service.exportPotree(folder)); // no hierarchy yet
    QTRY_COMPARE(failed.count(), 1);
    QVERIFY(failed.first().at(0).toString() == folder);
    failed.clear();

    constexpr std::uint64_t kPoints = 1'000'000;
    service.openGeneratedScene(kPoints, 7);
    const PipelineResult built = waitForBuild(finished, failed);
    QVERIFY(built.stats.complete);
    QTRY_VERIFY(!service.busy());

    QVERIFY(service.exportPotree(folder));
    QVERIFY(service.busy()); // the GUI thread returned at once; the worker writes
    QTRY_VERIFY_WITH_TIMEOUT(jobs.count() == 1, kBuildTimeoutMs);
    QTRY_VERIFY(!service.busy());
    QCOMPARE(failed.count(), 0);
    QVERIFY2(jobs.first().at(0).toString().contains(QStringLiteral("Exported 1000000 points")),
             qPrintable(jobs.first().at(0).toString()));
    QFile metadata(folder + QStringLiteral("/metadata.json"));
    QVERIFY(metadata.open(QIODevice::ReadOnly));
    QVERIFY(metadata.readAll().contains("\"points\": 1000000,"));
    QVERIFY(progress.count() >= 1);
    const auto last = progress.last();
    QCOMPARE(last.at(0).value<quint64>(), last.at(1).value<quint64>()); // ends at its total

    // Cancelled right after it starts: a message, no folder, no temporary folder.
    const QString cancelled = dir.filePath(QStringLiteral("cancelled"));
    QVERIFY(service.exportPotree(cancelled));
    service.cancel();
    QTRY_VERIFY_WITH_TIMEOUT(jobs.count() == 2, kBuildTimeoutMs);
    QTRY_VERIFY(!service.busy());
    QCOMPARE(failed.count(), 0);
    QVERIFY2(jobs.last().at(0).toString().contains(QStringLiteral("cancelled")),
             qPrintable(jobs.last().at(0).toString()));
    QVERIFY(!QFileInfo::exists(cancelled));
    const QStringList leftovers =
        QDir(dir.path()).entryList(QDir::AllEntries | QDir::Hidden | QDir::NoDotAndDotDot);
    QCOMPARE(leftovers, QStringList{QStringLiteral("potree")});
}

void TestBuilderService::cancelMidBuildEndsTheRun() {
    BuilderService service;
    service.setOptions(testOptions(8));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy progress(&service, &BuilderService::progressChanged);
    service.openGeneratedScene(3'000'000, 5);
    QTRY_VERIFY_WITH_TIMEOUT(progress.count() > 0, kBuildTimeoutMs);
    QElapsedTimer clock;
    clock.start();
    service.cancel();
    const PipelineResult result = waitForBuild(finished, failed);
    QVERIFY(result.cancelled);
    QVERIFY(!result.stats.complete);
    QVERIFY2(clock.elapsed() < 10'000, qPrintable(QString::number(clock.elapsed())));
    QTRY_VERIFY(!service.busy());
    QVERIFY(!service.hasCompleteCloud());
}

// Cancel while a PLY file is scanned for its bounds (before any point streams): the run ends
// cancelled, the file was never read into the sorter, and the previous cloud and hierarchy
// stay. The worker waits inside the scan until the GUI thread has seen the scan in the
// progress signal and pressed Cancel, so the order does not depend on timing.
// A PLY has no bounds in its header: while the file is scanned for them, the preview is the
// scan's own sample in a provisional frame (the scan is held mid-file here until that preview
// has arrived). (The sorter's preview follows while reading, when a poll falls in it.)
void TestBuilderService::firstPixelsComeFromTheBoundsPrePass() {
    QTemporaryDir dir;
    const QString path = writeAsciiScan(dir);

    std::mutex mutex;
    std::condition_variable released;
    bool release = false;
    std::atomic<int> reports{0};
    BuilderService service; // after what its worker's observer uses: destroyed first
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy previews(&service, &BuilderService::previewChanged);
    service.setPrePassObserver([&](std::uint64_t, std::uint64_t) {
        if (++reports == 4) { // three blocks sampled, most of the file still to scan
            std::unique_lock lock(mutex);
            released.wait_for(lock, std::chrono::seconds(60), [&] { return release; });
        }
    });
    service.open(path);
    QTRY_VERIFY_WITH_TIMEOUT(!previews.isEmpty(), kBuildTimeoutMs);
    const auto first = previews.first().at(0).value<PreviewSample>();
    QVERIFY(first.provisional);
    QVERIFY(first.positions.size() > 1000);
    for (const glm::vec3& p : first.positions) {
        QVERIFY(p.x >= 0.0f && p.y >= 0.0f && p.z >= 0.0f);
        QVERIFY(p.x <= 1.0f && p.y <= 1.0f && p.z <= 1.0f);
    }
    QVERIFY(reports.load() >= 4); // the scan is still held: these pixels came before the read
    {
        std::lock_guard lock(mutex);
        release = true;
    }
    released.notify_all();
    QVERIFY(waitForBuild(finished, failed).stats.complete);
    QTRY_VERIFY(!service.busy());
    service.setPrePassObserver({});
}

void TestBuilderService::cancelDuringTheBoundsPrePassKeepsThePreviousCloud() {
    QTemporaryDir dir;
    const QString path = writeAsciiScan(dir);

    std::mutex mutex;
    std::condition_variable pressed;
    bool cancelPressed = false;
    std::atomic<int> reports{0};
    BuilderService service; // after what its worker's observer uses: destroyed first
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy progress(&service, &BuilderService::progressChanged);
    service.openGeneratedScene(20'000, 3);
    QVERIFY(waitForBuild(finished, failed).stats.complete);
    QTRY_VERIFY(!service.busy());
    const auto keptHierarchy = service.hierarchy();
    const std::uint64_t reads = service.sourceReads();

    service.setPrePassObserver([&](std::uint64_t, std::uint64_t) {
        if (++reports == 2) { // after the first block
            std::unique_lock lock(mutex);
            pressed.wait_for(lock, std::chrono::seconds(60), [&] { return cancelPressed; });
        }
    });
    progress.clear();
    service.open(path);
    const auto scanning = [&] {
        for (const QList<QVariant>& signal : progress) {
            const auto p = signal.at(0).value<PipelineProgress>();
            if (p.phase == BuildPhase::Opening && p.bytesScanned > 0 &&
                p.bytesScanned < p.bytesToScan) {
                return true;
            }
        }
        return false;
    };
    QTRY_VERIFY_WITH_TIMEOUT(scanning(), kBuildTimeoutMs);
    service.cancel();
    {
        std::lock_guard lock(mutex);
        cancelPressed = true;
    }
    pressed.notify_all();
    const PipelineResult result = waitForBuild(finished, failed);
    QTRY_VERIFY(!service.busy());
    service.setPrePassObserver({});
    QVERIFY(result.cancelled);
    QCOMPARE(failed.count(), 0);
    QCOMPARE(reports.load(), 2); // the scan stopped at its next block
    const PipelineProgress last = service.pipeline().progress();
    QCOMPARE(last.phase, BuildPhase::Cancelled);
    QVERIFY(last.bytesScanned < last.bytesToScan);
    QCOMPARE(service.hierarchy(), keptHierarchy);
    QVERIFY(service.hasCompleteCloud());
    QCOMPARE(service.sourceReads(), reads);
    QCOMPARE(service.source()->kind, PipelineKind::GeneratedScene);
}

void TestBuilderService::destroyingMidBuildJoinsEveryThread() {
    std::weak_ptr<const Hierarchy> hierarchy;
    QElapsedTimer clock;
    {
        BuilderService service;
        service.setOptions(testOptions(8));
        QSignalSpy progress(&service, &BuilderService::hierarchyChanged);
        service.openGeneratedScene(3'000'000, 6);
        QTRY_VERIFY_WITH_TIMEOUT(progress.count() > 0, kBuildTimeoutMs);
        hierarchy = service.hierarchy();
        QVERIFY(!hierarchy.expired());
        QVERIFY(service.busy());
        clock.start();
    } // ~BuilderService: cancel, join the worker; the builder joins its master thread
    QVERIFY2(clock.elapsed() < 10'000, qPrintable(QString::number(clock.elapsed())));
    // The hierarchy (owned by the builder and the pipeline only) is gone: nothing still runs
    // that could hold it.
    QVERIFY(hierarchy.expired());
}

void TestBuilderService::newOpenWhileBusyReplacesTheRunningBuild() {
    OMICRON_REQUIRE_SHARED_FILE(path, "bunny.ply");
    BuilderService service;
    service.setOptions(testOptions(6));
    QSignalSpy finished(&service, &BuilderService::buildFinished);
    QSignalSpy failed(&service, &BuilderService::failed);
    QSignalSpy started(&service, &BuilderService::buildStarted);
    service.openGeneratedScene(3'000'000, 7);
    service.open(path); // never waits on the GUI thread
    QTRY_VERIFY_WITH_TIMEOUT(started.count() == 2, kBuildTimeoutMs);
    QTRY_VERIFY_WITH_TIMEOUT(finished.count() == 2, kBuildTimeoutMs);
    QVERIFY(finished.at(0).at(0).value<PipelineResult>().cancelled);
    const auto last = finished.at(1).at(0).value<PipelineResult>();
    QVERIFY(last.stats.complete);
    QCOMPARE(QString::fromStdString(last.source.path), path);
    QCOMPARE(failed.count(), 0);
}

QTEST_MAIN(TestBuilderService)
#include "tst_builderservice.moc"
