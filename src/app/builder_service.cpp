#include "builder_service.hpp"

#include "formats/omh_writer.hpp"
#include "formats/oms_writer.hpp"
#include "formats/potree_writer.hpp"
#include "io/cloud_export.hpp"

#include <QFileInfo>
#include <QMetaObject>
#include <exception>

namespace omicron {

BuilderService::BuilderService(QObject* parent)
    : QObject(parent), m_pipeline(std::make_unique<BuildPipeline>()) {
    qRegisterMetaType<PipelineProgress>();
    qRegisterMetaType<BuildStatistics>();
    qRegisterMetaType<PipelineResult>();
    qRegisterMetaType<PreviewSample>();
    qRegisterMetaType<CubeTransform>();
    m_poll.setInterval(kPollIntervalMs);
    connect(&m_poll, &QTimer::timeout, this, &BuilderService::poll);
}

BuilderService::~BuilderService() {
    shutdown();
}

void BuilderService::open(const QString& path) {
    const std::string file = path.toStdString();
    m_openJob = [file, path](const PipelineOptions& options) {
        return Job{QFileInfo(path).fileName(), true,
                   [file, options](BuildPipeline& pipeline) {
                       return JobOutcome{pipeline.run(file, options), {}};
                   },
                   path, true};
    };
    submit(m_openJob(m_options));
}

void BuilderService::openGeneratedScene(std::uint64_t points, std::uint64_t seed) {
    m_openJob = [points, seed](const PipelineOptions& options) {
        return Job{tr("generated scene"),
                   true,
                   [points, seed, options](BuildPipeline& pipeline) {
                       return JobOutcome{pipeline.runGeneratedScene(points, seed, options), {}};
                   },
                   {},
                   true};
    };
    submit(m_openJob(m_options));
}

QString BuilderService::sourceTitle() const {
    const auto source = m_pipeline->source();
    return source && !source->path.empty()
               ? QFileInfo(QString::fromStdString(source->path)).fileName()
               : tr("generated scene");
}

bool BuilderService::rebuild(const BuildOptions& options) {
    m_options.build = options;
    // While the cloud is still being read or sorted (or its run was cancelled) there is no
    // complete sorted list to reuse: run the last source again with the new parameters.
    // The same when a new source is about to replace the kept cloud: the rebuild is meant for
    // the cloud being opened, not for the one on screen.
    const bool openingSource =
        (m_pending && m_pending->opensSource) ||
        (m_busy && m_currentOpensSource && m_pipeline->progress().phase < BuildPhase::Building);
    if (!m_pipeline->hasCompleteCloud() || openingSource) {
        if (!m_openJob) {
            emit failed({}, tr("Nothing to rebuild: no cloud is loaded."));
            return false;
        }
        submit(m_openJob(m_options));
        return true;
    }
    submit({sourceTitle(),
            true,
            [options](BuildPipeline& pipeline) {
                return JobOutcome{pipeline.rebuild(options), {}};
            },
            {}});
    return true;
}

bool BuilderService::exportSortedStream(const QString& path) {
    return submitCloudExport(path, [](const std::string& file, const SortedCloud& cloud) {
        writeOms(file, cloud, cloud.sortedEnd());
        return tr("Wrote the sorted stream %1").arg(QString::fromStdString(file));
    });
}

bool BuilderService::exportPoints(const QString& path, const std::optional<ClipBox>& clip) {
    return submitCloudExport(path, [clip](const std::string& file, const SortedCloud& cloud) {
        const std::uint64_t written = exportCloudPoints(file, cloud, clip);
        return (clip ? tr("Exported %1 points inside the clip box to %2")
                     : tr("Exported %1 points to %2"))
            .arg(written)
            .arg(QString::fromStdString(file));
    });
}

bool BuilderService::submitCloudExport(const QString& path, CloudWriter write) {
    const auto cloud = m_pipeline->sortedCloud();
    if (!cloud || !cloud->complete()) {
        emit failed(path, tr("Nothing to export: wait until the cloud is completely sorted."));
        return false;
    }
    submit({QFileInfo(path).fileName(), false,
            [file = path.toStdString(), cloud, write](BuildPipeline&) {
                return JobOutcome{{}, write(file, *cloud)};
            },
            path});
    return true;
}

void BuilderService::openHierarchy(const QString& path) {
    open(path); // BuildPipeline::run() recognises a .omh file and loads it (pipeline 3)
}

bool BuilderService::saveHierarchy(const QString& path) {
    const auto hierarchy = m_pipeline->hierarchy();
    if (!hierarchy || !hierarchy->publishedCut().complete || m_busy) {
        emit failed(path, tr("Nothing to save: wait until the hierarchy is complete."));
        return false;
    }
    const std::string file = path.toStdString();
    const omh::BuildInfo info =
        omhBuildInfo(m_pipeline->hierarchyOptions(), m_pipeline->statistics());
    submit({QFileInfo(path).fileName(), false,
            [file, hierarchy, info, path](BuildPipeline&) {
                writeOmh(file, *hierarchy, info); // temporary file + rename: no partial file
                return JobOutcome{{}, tr("Saved the hierarchy %1").arg(path)};
            },
            path});
    return true;
}

bool BuilderService::exportPotree(const QString& folder) {
    const auto hierarchy = m_pipeline->hierarchy();
    if (!hierarchy || !hierarchy->publishedCut().complete || m_busy) {
        emit failed(folder, tr("Nothing to export: wait until the hierarchy is complete."));
        return false;
    }
    PotreeExportOptions options;
    options.name = sourceTitle().section(QLatin1Char('.'), 0, 0).toStdString();
    // A loaded .omh's cloud holds the parents' copies: its header's count is the input's.
    options.inputPoints = m_pipeline->statistics().inputPoints;
    Job job{QFileInfo(folder).fileName(), false,
            [this, file = folder.toStdString(), hierarchy, options,
             folder](BuildPipeline& pipeline) mutable {
                options.cancel = &pipeline.cancelFlag();
                options.onProgress = [this](std::uint64_t done, std::uint64_t total) {
                    m_jobTotal.store(total, std::memory_order_relaxed);
                    m_jobDone.store(done, std::memory_order_relaxed);
                };
                try {
                    const PotreeExportSummary summary =
                        omicron::exportPotree(*hierarchy, file, options);
                    return JobOutcome{
                        {},
                        tr("Exported %1 points (%2 dropped by leaf collapse) to the Potree "
                           "folder %3")
                            .arg(summary.points)
                            .arg(summary.droppedPoints)
                            .arg(folder)};
                } catch (const PotreeExportCancelled&) {
                    return JobOutcome{{}, tr("Potree export to %1 cancelled").arg(folder)};
                }
            },
            folder};
    job.reportsProgress = true;
    submit(std::move(job));
    return true;
}

void BuilderService::submit(Job job) {
    if (m_busy) {
        // Last request wins; the running job stops at its next cancellation check and
        // onWorkerDone() starts this one, so the GUI thread never waits here.
        m_pending = std::move(job);
        m_pipeline->cancel();
        return;
    }
    startJob(std::move(job));
}

void BuilderService::startJob(Job job) {
    joinWorker();              // the previous worker has already posted its result: returns at once
    m_pipeline->resetCancel(); // before the thread starts: a cancel() after this one counts
    setBusy(true);
    m_currentIsBuild = job.build;
    m_currentOpensSource = job.opensSource;
    m_currentReportsProgress = job.reportsProgress;
    m_jobDone = 0;
    m_jobTotal = 0;
    if (job.reportsProgress) {
        m_poll.start();
    }
    if (job.build) {
        // Polls before the worker's run starts would see the previous run's final phase.
        m_staleGeneration = m_pipeline->progress().generation;
        m_buildClock.start();
        m_lastProgress = {};
        m_lastPreviewPoints = 0;
        m_lastPreviewProvisional = false;
        emit buildStarted(job.title);
        m_poll.start();
    }
    m_worker = std::thread([this, job = std::move(job)]() mutable {
        JobOutcome outcome;
        QString error;
        try {
            outcome = job.work(*m_pipeline);
        } catch (const std::exception& e) {
            error = QString::fromStdString(e.what());
        } catch (...) {
            error = QStringLiteral("unknown error");
        }
        // Hand the outcome to the GUI thread; dropped if the service is gone by then (the
        // destructor joined this thread first, so `this` is valid while posting).
        QMetaObject::invokeMethod(
            this,
            [this, job = std::move(job), outcome = std::move(outcome), error]() mutable {
                onWorkerDone(job, std::move(outcome), error);
            },
            Qt::QueuedConnection);
    });
}

void BuilderService::onWorkerDone(const Job& job, JobOutcome outcome, const QString& error) {
    joinWorker();
    if (job.build || job.reportsProgress) {
        m_poll.stop();
        poll(); // the final numbers, whatever the timer phase
    }
    if (!error.isEmpty()) {
        emit failed(job.path, error);
    } else if (outcome.result) {
        emit buildFinished(*outcome.result);
    } else if (!outcome.message.isEmpty()) {
        emit jobFinished(outcome.message);
    }
    if (m_pending) {
        Job next = std::move(*m_pending);
        m_pending.reset();
        startJob(std::move(next));
        return;
    }
    setBusy(false);
}

void BuilderService::cancel() {
    m_pending.reset();
    m_pipeline->cancel();
}

void BuilderService::shutdown() {
    m_pending.reset();
    m_pipeline->cancel();
    m_poll.stop();
    joinWorker();
}

void BuilderService::joinWorker() {
    if (m_worker.joinable()) {
        m_worker.join();
    }
}

double BuilderService::buildSeconds() const {
    return m_buildClock.isValid() ? m_buildClock.nsecsElapsed() * 1e-9 : 0.0;
}

void BuilderService::setBusy(bool busy) {
    if (m_busy != busy) {
        m_busy = busy;
        emit busyChanged(busy);
    }
}

void BuilderService::poll() {
    if (!m_currentIsBuild) {
        if (m_currentReportsProgress && m_jobTotal.load(std::memory_order_relaxed) > 0) {
            emit jobProgressChanged(m_jobDone.load(std::memory_order_relaxed),
                                    m_jobTotal.load(std::memory_order_relaxed));
        }
        return;
    }
    const PipelineProgress progress = m_pipeline->progress();
    const auto hierarchy = m_pipeline->hierarchy();
    if (hierarchy != m_lastHierarchy) {
        m_lastHierarchy = hierarchy;
        emit hierarchyChanged(hierarchy);
    }
    if (progress.phase == BuildPhase::Reading || progress.scanningBounds()) {
        // While a PLY or XYZ file is scanned for its bounds, the scan's own sample in a
        // provisional frame; from the read on, the sorter's.
        PreviewSample preview = m_pipeline->preview();
        const auto source = m_pipeline->source();
        const bool usable =
            preview.provisional || (progress.phase == BuildPhase::Reading && source.has_value());
        if (usable && !preview.positions.empty() &&
            (preview.pointsSeen != m_lastPreviewPoints ||
             preview.provisional != m_lastPreviewProvisional)) {
            m_lastPreviewPoints = preview.pointsSeen;
            m_lastPreviewProvisional = preview.provisional;
            emit previewChanged(preview, source ? source->cube : CubeTransform{});
        }
    }
    if (progress.generation == m_staleGeneration) {
        return;
    }
    emit progressChanged(progress);
    emit statisticsChanged(m_pipeline->statistics());
    m_lastProgress = progress;
}

} // namespace omicron
