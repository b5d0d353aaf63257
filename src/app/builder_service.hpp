// BuilderService: the desktop application's owner of the build pipeline. It runs the
// pipeline (reader -> sorter -> builder, see core/build_pipeline.hpp) and the long file jobs
// (exports, hierarchy files) on one worker std::thread, and reports to the GUI thread through
// signals: progress and statistics at most 10 times a second (a QTimer on the GUI thread polls
// the pipeline's atomics, so worker threads never touch Qt objects), and every outcome
// (finished, failed with the file and the problem, cancelled).
//
// The GUI thread never waits for the build: a request that arrives while a job runs cancels
// it and starts once the worker has returned; the destructor cancels and joins, which is
// prompt because every pipeline stage checks the cancel flag between batches.
#pragma once

#include "pipeline/build_pipeline.hpp"
#include "points/clip_box.hpp"

#include <QElapsedTimer>
#include <QObject>
#include <QString>
#include <QTimer>
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace omicron {

class BuilderService : public QObject {
    Q_OBJECT
public:
    // Polling period of the progress timer: 10 Hz, the bound on signal rate.
    static constexpr int kPollIntervalMs = 100;

    explicit BuilderService(QObject* parent = nullptr);
    ~BuilderService() override; // cancels and joins the worker

    // Parameters of the next open (and the defaults of rebuild()).
    PipelineOptions options() const { return m_options; }
    void setOptions(const PipelineOptions& options) { m_options = options; }

    // Starts pipeline 1 (PLY/LAS/LAZ/XYZ) or 2 (.oms) for `path`. What File -> Open calls.
    void open(const QString& path);
    // Starts the built-in generated scene (pipeline 1 from memory).
    void openGeneratedScene(std::uint64_t points = kDefaultScenePoints,
                            std::uint64_t seed = kDefaultSceneSeed);
    // A new hierarchy with `options` from the kept sorted cloud: no file is read.
    // Returns false (and emits failed) when no complete sorted cloud is kept.
    bool rebuild(const BuildOptions& options);
    // Writes the kept sorted cloud as .oms, or as PLY/LAS (by extension) in Morton order.
    bool exportSortedStream(const QString& path);
    // With `clip` (source units): only the points inside the clip box.
    bool exportPoints(const QString& path, const std::optional<ClipBox>& clip = std::nullopt);
    // Pipeline 3: loads a .omh hierarchy file; and writes the current hierarchy as .omh.
    void openHierarchy(const QString& path);
    bool saveHierarchy(const QString& path);
    // Writes the current (complete) hierarchy as a Potree 2.0 folder, each input point once
    // (formats/potree_writer.hpp): progress through jobProgressChanged, cancel() stops it and
    // leaves neither the folder nor its temporary one.
    bool exportPotree(const QString& folder);

    // Stops the running job (no-op when idle), also during the bounds pre-pass of a PLY or
    // XYZ file (the kept cloud and hierarchy then stay); a pending request is dropped too.
    void cancel();
    // Called on the worker thread as the bounds pre-pass of a file being opened advances
    // (progressChanged carries the same numbers at 10 Hz). Set it while no job runs.
    void setPrePassObserver(BuildPipeline::PrePassObserver observer) {
        m_pipeline->setPrePassObserver(std::move(observer));
    }
    // Cancels and joins the worker (blocks only for the worker's next cancellation check).
    void shutdown();

    bool busy() const { return m_busy; }
    const BuildPipeline& pipeline() const { return *m_pipeline; }
    std::shared_ptr<const Hierarchy> hierarchy() const { return m_pipeline->hierarchy(); }
    std::optional<PipelineSource> source() const { return m_pipeline->source(); }
    // How the kept source is named to the user: its file name, or "generated scene".
    QString sourceTitle() const;
    bool hasCompleteCloud() const { return m_pipeline->hasCompleteCloud(); }
    // Files (or scenes) read so far: a rebuild reads none.
    std::uint64_t sourceReads() const { return m_pipeline->sourceReads(); }
    // Seconds since the current (or last) build started.
    double buildSeconds() const;

signals:
    void busyChanged(bool busy);
    // A build started: `title` names the source ("bunny.ply", "generated scene").
    void buildStarted(const QString& title);
    void progressChanged(const omicron::PipelineProgress& progress);
    void statisticsChanged(const omicron::BuildStatistics& statistics);
    // A new hierarchy exists (also while it is still being built).
    void hierarchyChanged(std::shared_ptr<const omicron::Hierarchy> hierarchy);
    // The sorter's preview sample while pipeline 1 reads.
    void previewChanged(const omicron::PreviewSample& preview, const omicron::CubeTransform& cube);
    void buildFinished(const omicron::PipelineResult& result);
    // A file job (export, save) succeeded or was cancelled: `message` says what was written.
    void jobFinished(const QString& message);
    // A file job that reports progress (the Potree export): `done` of `total` units, at most
    // 10 times a second while it runs.
    void jobProgressChanged(quint64 done, quint64 total);
    // Any failure: the file involved (may be empty) and the problem, for an error dialog.
    void failed(const QString& path, const QString& message);

private:
    // What a job left: a build's result, or a file job's message for the status bar.
    struct JobOutcome {
        std::optional<PipelineResult> result;
        QString message;
    };
    struct Job {
        QString title;
        bool build = true; // builds report progress and end with buildFinished
        std::function<JobOutcome(BuildPipeline&)> work;
        QString path;                 // the file involved, for error messages
        bool opensSource = false;     // reads a file or the scene (replaces the kept cloud)
        bool reportsProgress = false; // a file job that sets m_jobDone / m_jobTotal
    };

    // Writes the kept sorted cloud to a file on the worker; returns the status-bar message.
    using CloudWriter = std::function<QString(const std::string& file, const SortedCloud& cloud)>;
    // Refuses (failed signal) until the cloud is completely sorted.
    bool submitCloudExport(const QString& path, CloudWriter write);
    void submit(Job job);
    void startJob(Job job);
    void joinWorker();
    void poll();
    void setBusy(bool busy);
    void onWorkerDone(const Job& job, JobOutcome outcome, const QString& error);

    std::unique_ptr<BuildPipeline> m_pipeline;
    PipelineOptions m_options;
    std::thread m_worker;
    bool m_busy = false;
    std::optional<Job> m_pending;
    std::function<Job(const PipelineOptions&)> m_openJob; // the last open, for any options
    QTimer m_poll;
    QElapsedTimer m_buildClock;
    bool m_currentIsBuild = false;
    bool m_currentOpensSource = false;
    bool m_currentReportsProgress = false;
    // A file job's progress, written by the worker, polled by the timer.
    std::atomic<std::uint64_t> m_jobDone{0};
    std::atomic<std::uint64_t> m_jobTotal{0};
    std::shared_ptr<const Hierarchy> m_lastHierarchy;
    PipelineProgress m_lastProgress;
    std::uint64_t m_staleGeneration = 0;
    std::uint64_t m_lastPreviewPoints = 0;
    bool m_lastPreviewProvisional = false;
};

} // namespace omicron

Q_DECLARE_METATYPE(omicron::PipelineProgress)
Q_DECLARE_METATYPE(omicron::BuildStatistics)
Q_DECLARE_METATYPE(omicron::PipelineResult)
Q_DECLARE_METATYPE(omicron::PreviewSample)
Q_DECLARE_METATYPE(omicron::CubeTransform)
