// render_bench FILE [--size WxH] [--frames N]: GPU frame time of CloudView on this machine's
// OpenGL (Mesa llvmpipe in CI), on a scripted orbit around the finished hierarchy, for several
// point budgets, once with GL_POINTS (RenderMode::Points) and once with the compute point
// rasterizer (RenderMode::ComputePoints) on the same orbit. Baseline in the same run, per
// path: the same frames with a budget of one node (clear, front, readback and the path's fixed
// passes: what a frame costs without points), so ns_per_point isolates the points; a
// phase=compare line per budget gives compute / points ratios; phase=edl the same orbit with
// and without eye-dome lighting. Needs a display (xvfb-run on
// headless machines).
#include "bench_timing.hpp"
#include "cloud_view.hpp"
#include "pipeline/build_pipeline.hpp"

#include <QApplication>
#include <QImage>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace omicron;

namespace {

std::shared_ptr<const Hierarchy> buildHierarchy(const std::string& path) {
    BuildPipeline pipeline;
    pipeline.run(path, {BuildOptions{}, kDefaultSortChunks});
    return pipeline.hierarchy();
}

double percentile(std::vector<double> values, double p) {
    std::sort(values.begin(), values.end());
    const auto index = static_cast<std::size_t>(std::lround(p * static_cast<double>(values.size() - 1)));
    return values[index];
}

struct PathResult {
    double frameMsMedian = 0.0, frameMsP95 = 0.0, frontMsMedian = 0.0;
    double pointsMedian = 0.0;
};

// One orbit of `frames` frames around the cloud; every frame read back (grabFramebuffer), so
// the GPU work is finished inside the timing.
PathResult runPath(CloudView& view, const ViewCamera& start, int frames, RenderMode mode,
                   std::size_t budget, EdlMode edl = EdlMode::Off) {
    RenderSettings settings = view.renderSettings();
    settings.mode = mode;
    settings.edl = edl;
    settings.pointBudget = budget;
    settings.uploadBudgetBytes = std::size_t{1} << 30; // measure drawing, not upload pacing
    view.setRenderSettings(settings);
    std::vector<double> frameMs, frontMs, points;
    for (int warm = -20; warm < frames; ++warm) {
        ViewCamera camera = start;
        camera.orbit(std::max(warm, 0) * 720.0 / frames, 0.0); // one turn over the path
        view.setCamera(camera);
        const auto begin = bench::Clock::now();
        const QImage image = view.grabFramebuffer();
        const double ms = bench::secondsSince(begin) * 1e3;
        if (warm >= 0 && !image.isNull()) {
            frameMs.push_back(ms);
            frontMs.push_back(view.lastFrameStats().frontMs);
            points.push_back(static_cast<double>(view.lastFrameStats().pointsDrawn));
        }
    }
    if (frameMs.empty()) {
        return {};
    }
    return {percentile(frameMs, 0.5), percentile(frameMs, 0.95), percentile(frontMs, 0.5),
            percentile(points, 0.5)};
}

double nsPerPoint(const PathResult& result, const PathResult& baseline) {
    const double pointMs = std::max(result.frameMsMedian - baseline.frameMsMedian, 0.0);
    return result.pointsMedian > 0 ? pointMs * 1e6 / result.pointsMedian : 0.0;
}

struct PathChoice {
    const char* name;
    RenderMode mode;
};
constexpr PathChoice kPaths[] = {{"points", RenderMode::Points},
                                 {"compute", RenderMode::ComputePoints}};

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: render_bench FILE [--size WxH] [--frames N]\n");
        return 2;
    }
    if (std::getenv("DISPLAY") == nullptr && std::getenv("WAYLAND_DISPLAY") == nullptr) {
        std::fprintf(stderr, "render_bench needs a display (run under xvfb-run)\n");
        return 2;
    }
    int width = 1280, height = 800, frames = 60;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (std::strcmp(argv[i], "--size") == 0) {
            std::sscanf(argv[i + 1], "%dx%d", &width, &height);
        } else if (std::strcmp(argv[i], "--frames") == 0) {
            frames = std::max(2, std::atoi(argv[i + 1]));
        }
    }
    const std::string path = argv[1];
    const auto hierarchy = buildHierarchy(path);

    QApplication app(argc, argv);
    CloudView view;
    view.setAttribute(Qt::WA_DontShowOnScreen);
    view.resize(width, height);
    view.show();
    RenderSettings settings;
    settings.showAxes = false;
    view.setRenderSettings(settings);
    view.setHierarchy(hierarchy);
    (void)view.renderImage(QSize(64, 64)); // bounds and auto-fit
    const ViewCamera start = view.camera();
    const std::string renderer = view.glRendererName().toStdString();

    const int computeAvailable = view.computePointsAvailable() ? 1 : 0;
    PathResult baselines[2];
    for (int path = 0; path < 2; ++path) {
        baselines[path] = runPath(view, start, frames, kPaths[path].mode, 1);
        const PathResult& empty = baselines[path];
        std::printf("bench=render phase=baseline_no_points path=%s renderer=\"%s\" "
                    "compute_available=%d size=%dx%d frames=%d frame_ms_median=%.2f "
                    "frame_ms_p95=%.2f front_ms_median=%.3f\n",
                    kPaths[path].name, renderer.c_str(), computeAvailable, width, height, frames,
                    empty.frameMsMedian, empty.frameMsP95, empty.frontMsMedian);
    }
    for (std::size_t budget : {std::size_t{250'000}, std::size_t{1'000'000}, std::size_t{0}}) {
        PathResult results[2];
        double nsPer[2];
        // Both paths on the same orbit and budget, one after the other.
        for (int path = 0; path < 2; ++path) {
            results[path] = runPath(view, start, frames, kPaths[path].mode, budget);
            const PathResult& result = results[path];
            nsPer[path] = nsPerPoint(result, baselines[path]);
            std::printf("bench=render phase=orbit path=%s point_budget=%zu size=%dx%d frames=%d "
                        "points_drawn_median=%.0f frame_ms_median=%.2f frame_ms_p95=%.2f "
                        "front_ms_median=%.3f ns_per_point=%.1f fps=%.1f\n",
                        kPaths[path].name, budget, width, height, frames, result.pointsMedian,
                        result.frameMsMedian, result.frameMsP95, result.frontMsMedian, nsPer[path],
                        result.frameMsMedian > 0 ? 1000.0 / result.frameMsMedian : 0.0);
        }
        const auto ratio = [](double compute, double points) {
            return points > 0 ? compute / points : 0.0;
        };
        std::printf("bench=render phase=compare point_budget=%zu compute_available=%d "
                    "points_ns_per_point=%.1f compute_ns_per_point=%.1f "
                    "ns_per_point_ratio_compute_over_points=%.3f "
                    "frame_ms_ratio_compute_over_points=%.3f faster=%s\n",
                    budget, computeAvailable, nsPer[0], nsPer[1], ratio(nsPer[1], nsPer[0]),
                    ratio(results[1].frameMsMedian, results[0].frameMsMedian),
                    results[1].frameMsMedian < results[0].frameMsMedian ? "compute" : "points");
    }
    // Eye-dome lighting: the same orbit with and without it (one full-screen pass reading
    // nine depths a pixel), at the default budget.
    const PathResult plain = runPath(view, start, frames, RenderMode::ComputePoints, 1'000'000);
    const PathResult shaded =
        runPath(view, start, frames, RenderMode::ComputePoints, 1'000'000, EdlMode::On);
    std::printf("bench=render phase=edl path=compute point_budget=1000000 size=%dx%d frames=%d "
                "frame_ms_median_off=%.2f frame_ms_median_on=%.2f edl_ms=%.2f\n",
                width, height, frames, plain.frameMsMedian, shaded.frameMsMedian,
                shaded.frameMsMedian - plain.frameMsMedian);
    return 0;
}
