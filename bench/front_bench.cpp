// Render-front CPU cost and insertion delay on a scripted camera path, while a build runs
// and after it (the CPU part of the render benchmark; the GPU part belongs to the widget).
//
// usage: front_bench FILE [--depth D] [--feed-seconds S] [--after-frames N] [--threshold PX]
//   (e.g. ../shared/data/autzen_south.ply, depth 7)
// The file is read and Morton-sorted first; then a HierarchyBuilder receives the sorted cloud
// in 256 ranges paced over S seconds (default 2: a stream arriving, as from a .oms file or a
// sorter), while this thread evaluates a Front at 60 Hz on an orbit that zooms in and out,
// with the default FrontOptions (100 px threshold unless --threshold, 4 M point budget, 2 ms
// CPU budget). After
// the build, N more frames (default 300) on the same path. Printed per phase: evaluation ms
// per frame (median, p95, max), front size, visible points; then the insertion delay (leaf
// published -> substituted, ms and 60 Hz frames; leaf settled -> substituted, evaluations)
// and, as the in-run baseline, a whole unsegmented sweep of the final front.
#include "bench_timing.hpp"
#include "build/hierarchy_builder.hpp"
#include "front/front.hpp"
#include "front/front_projection.hpp"
#include "io/point_reader.hpp"
#include "sort/morton_sorter.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace {

using omicron::bench::Clock;
using omicron::bench::quantile;
using omicron::bench::secondsSince;

constexpr double kFrameSeconds = 1.0 / 60.0;

template <typename T> double maximum(const std::vector<T>& values) {
    return values.empty() ? 0.0 : static_cast<double>(*std::max_element(values.begin(), values.end()));
}

struct Phase {
    std::vector<double> evaluationMs;
    std::vector<std::size_t> frontSize, visiblePoints, placeholders;
    std::size_t sweeps = 0, branched = 0, pruned = 0, substituted = 0, overBudget = 0;

    void add(const omicron::FrontEvaluation& r) {
        evaluationMs.push_back(r.cpuMs);
        frontSize.push_back(r.frontSize);
        visiblePoints.push_back(r.visiblePoints);
        placeholders.push_back(r.placeholders);
        sweeps += r.finishedSweep ? 1 : 0;
        branched += r.branched;
        pruned += r.pruned;
        substituted += r.substituted;
        overBudget += r.overBudget ? 1 : 0;
    }

    void print(const char* name) const {
        std::printf("bench=front phase=%s frames=%zu eval_ms_median=%.3f eval_ms_p95=%.3f "
                    "eval_ms_max=%.3f front_size_median=%.0f front_size_max=%.0f "
                    "visible_points_median=%.0f visible_points_max=%.0f placeholders_max=%.0f "
                    "sweeps=%zu branched=%zu pruned=%zu substituted=%zu over_budget_frames=%zu\n",
                    name, evaluationMs.size(), quantile(evaluationMs, 0.5),
                    quantile(evaluationMs, 0.95), maximum(evaluationMs), quantile(frontSize, 0.5),
                    maximum(frontSize), quantile(visiblePoints, 0.5), maximum(visiblePoints),
                    maximum(placeholders), sweeps, branched, pruned, substituted, overBudget);
        std::fflush(stdout);
    }
};

// The scripted path: an orbit (one turn in 8 s) around the cloud's centre, zooming from far
// (the whole cloud) to close (a few cells) and back every 6 s.
omicron::FrontCamera cameraAt(double seconds, const glm::dvec3& target) {
    const double azimuth = 2.0 * 3.14159265358979 * seconds / 8.0;
    const double zoom = 0.5 + 0.5 * std::cos(2.0 * 3.14159265358979 * seconds / 6.0);
    const double distance = 0.15 + 1.6 * zoom;
    const double elevation = 0.6;
    const glm::dvec3 eye =
        target + distance * glm::dvec3(std::cos(azimuth) * std::cos(elevation),
                                       std::sin(azimuth) * std::cos(elevation), std::sin(elevation));
    return omicron::perspectiveCamera(eye, target, 60.0 * 3.14159265358979 / 180.0, 16.0 / 9.0,
                                      1080.0);
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: front_bench FILE [--depth D] [--feed-seconds S] [--after-frames N] "
                     "[--threshold PX]\n");
        return 2;
    }
    const std::string path = argv[1];
    int depth = 7;
    double feedSeconds = 2.0;
    int afterFrames = 300;
    omicron::FrontOptions options; // the defaults a viewer starts with
    for (int i = 2; i + 1 < argc; i += 2) {
        if (std::strcmp(argv[i], "--depth") == 0) {
            depth = std::atoi(argv[i + 1]);
        } else if (std::strcmp(argv[i], "--feed-seconds") == 0) {
            feedSeconds = std::atof(argv[i + 1]);
        } else if (std::strcmp(argv[i], "--threshold") == 0) {
            options.projectionThresholdPx = std::atof(argv[i + 1]);
        } else if (std::strcmp(argv[i], "--after-frames") == 0) {
            afterFrames = std::atoi(argv[i + 1]);
        } else {
            std::fprintf(stderr, "front_bench: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    try {
        std::shared_ptr<const omicron::SortedCloud> cloud;
        {
            auto reader = omicron::openPointCloud(path);
            omicron::sortPointCloud(
                *reader, {}, [](const omicron::SortedCloud&, std::size_t, std::size_t) {},
                [&](const omicron::IncrementalMortonSorter& sorter) { cloud = sorter.cloud(); });
        }
        const std::size_t points = cloud->sortedEnd();
        glm::dvec3 centre(0.0);
        for (const glm::vec3& p : cloud->positions().first(points)) {
            centre += glm::dvec3(p);
        }
        centre /= std::max<double>(1.0, static_cast<double>(points));

        omicron::BuildOptions buildOptions;
        buildOptions.maxLevel = depth;
        omicron::HierarchyBuilder builder(cloud, buildOptions);
        const auto hierarchy = builder.sharedHierarchy();
        const std::size_t ranges = 256;
        std::thread feeder([&] {
            const auto start = Clock::now();
            for (std::size_t r = 0; r < ranges; ++r) {
                const std::size_t begin = points * r / ranges, end = points * (r + 1) / ranges;
                std::this_thread::sleep_until(
                    start + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(feedSeconds * double(r) / ranges)));
                if (end > begin) {
                    builder.onSortedRange(*cloud, begin, end);
                }
            }
            builder.finish();
        });

        omicron::Front front(hierarchy);
        Phase building, after;
        std::vector<double> delayMs;
        std::vector<std::uint32_t> settledEvaluations;
        const auto start = Clock::now();
        int frame = 0, framesAfter = 0;
        double buildSeconds = 0.0;
        for (;; ++frame) {
            std::this_thread::sleep_until(
                start + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(frame * kFrameSeconds)));
            const bool complete = hierarchy->publishedCut().complete;
            if (complete && buildSeconds == 0.0) {
                buildSeconds = secondsSince(start);
            }
            if (complete && front.placeholderCount() == 0 && framesAfter++ >= afterFrames) {
                break;
            }
            const omicron::FrontEvaluation result =
                front.evaluate(cameraAt(frame * kFrameSeconds, centre), options);
            (complete ? after : building).add(result);
            for (const double seconds : front.takeSubstitutionDelays()) {
                delayMs.push_back(seconds * 1e3);
            }
            const auto evaluations = front.takeSubstitutionEvaluationDelays();
            settledEvaluations.insert(settledEvaluations.end(), evaluations.begin(),
                                      evaluations.end());
        }
        feeder.join();
        builder.wait();
        const omicron::BuildStatistics stats = builder.statistics();

        // Baseline: the same front evaluated whole (no CPU budget) on a still camera.
        omicron::FrontOptions whole = options;
        whole.cpuBudgetMs = 0.0;
        Phase wholeSweep;
        for (int i = 0; i < 30; ++i) {
            wholeSweep.add(front.evaluate(cameraAt(frame * kFrameSeconds, centre), whole));
        }

        std::printf("bench=front file=%s points=%zu depth=%d leaves=%llu nodes=%llu "
                    "feed_s=%.2f build_s=%.2f frames=%d threshold_px=%.1f point_budget=%zu "
                    "cpu_budget_ms=%.1f\n",
                    path.c_str(), points, depth,
                    static_cast<unsigned long long>(stats.levels[depth].leaves +
                                                    stats.collapsedLeaves),
                    static_cast<unsigned long long>(stats.totalNodes()), feedSeconds,
                    buildSeconds, frame, options.projectionThresholdPx, options.pointBudget,
                    options.cpuBudgetMs);
        building.print("during_build");
        after.print("after_build");
        wholeSweep.print("whole_sweep_baseline");
        std::vector<double> delayFrames;
        for (const double ms : delayMs) {
            delayFrames.push_back(ms / (kFrameSeconds * 1e3));
        }
        std::printf("bench=front insertion_delay leaves=%zu ms_median=%.1f ms_p95=%.1f "
                    "ms_max=%.1f frames_median=%.1f frames_p95=%.1f frames_max=%.1f "
                    "settled_to_drawn_evals_median=%.0f settled_to_drawn_evals_p95=%.0f "
                    "settled_to_drawn_evals_max=%.0f\n",
                    delayMs.size(), quantile(delayMs, 0.5), quantile(delayMs, 0.95),
                    maximum(delayMs), quantile(delayFrames, 0.5), quantile(delayFrames, 0.95),
                    maximum(delayFrames), quantile(settledEvaluations, 0.5),
                    quantile(settledEvaluations, 0.95), maximum(settledEvaluations));
        // Targets: <= 2 ms median per frame; a leaf drawn within 3 frames of settling.
        const double medianMs = std::max(quantile(building.evaluationMs, 0.5),
                                         quantile(after.evaluationMs, 0.5));
        std::printf("bench=front targets eval_ms_median=%.3f eval_target_ms=2 eval_met=%s "
                    "settled_to_drawn_frames_max=%.0f drawn_target_frames=3 drawn_met=%s\n",
                    medianMs, medianMs <= 2.0 ? "yes" : "no", maximum(settledEvaluations),
                    maximum(settledEvaluations) <= 3.0 ? "yes" : "no");
        return 0;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "front_bench: %s\n", error.what());
        return 1;
    }
}
