// Opening a saved hierarchy (.omh) with its points paged in on demand under a memory budget,
// against loading the whole file and against reading its bytes (the baselines, same run).
//
// usage: omh_paging_bench FILE [--budget SIZE | --whole] [--views N] [--width PX]
//   FILE a .omh, or any cloud (built and saved to a temporary .omh first, removed at the end).
//   SIZE as the CLI takes it (512M, 4G). --whole loads every point (pipeline 3 as before).
// A front (the view's, without GL) is driven by orthographic cameras of --width pixels
// (default 1280) across their box, threshold 16 px, point budget 1 M (the app's defaults):
// first the whole cloud, then N (default 8) close-ups spread over the cloud, each held until
// the front changes nothing with no load outstanding (full detail of that view).
// Printed as key=value:
//   file_mb, raw_read_ms (reading the file's bytes: the I/O baseline), open_ms (header, level
//   table and every node; with --whole every point too), first_pixels_ms (open -> the root
//   is drawable), overview_ms, view_full_detail_ms_median/_max (camera stop -> full detail),
//   loads, evictions, read_mb, resident_mb, budget_mb, rss_after_open_mb,
//   rss_after_overview_mb, rss_end_mb (/proc/self/statm) and peak_rss_mb (getrusage).
// Run it once per configuration: the peak RSS is the process's. bench/out_of_core.sh makes a
// large .omh from a real scan and runs every configuration.
#include "bench_scratch.hpp"
#include "bench_timing.hpp"
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "front/front.hpp"
#include "front/front_settle.hpp"
#include "memory_budget.hpp"
#include "pipeline/build_pipeline.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <string>
#include <sys/resource.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace {

using omicron::bench::Clock;
using omicron::bench::secondsSince;
using namespace omicron;

double peakRssMb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// Resident now, to tell the phases apart; the peak is getrusage's.
double currentRssMb() { return static_cast<double>(processResidentSet().bytes) / (1 << 20); }

double rawReadMs(const std::string& path) {
    const auto start = Clock::now();
    const int fd = open(path.c_str(), O_RDONLY);
    if (fd < 0) {
        return 0.0;
    }
    std::vector<char> buffer(std::size_t{8} << 20);
    while (read(fd, buffer.data(), buffer.size()) > 0) {
    }
    close(fd);
    return secondsSince(start) * 1e3;
}

FrontCamera orthographic(double cx, double cy, double half, double widthPx) {
    FrontCamera camera;
    camera.orthographic = true;
    camera.pixelsPerUnitAtUnitDistance = widthPx / (2.0 * half);
    camera.viewProjection = glm::dmat4(1.0);
    camera.viewProjection[0][0] = camera.viewProjection[1][1] = 1.0 / half;
    camera.viewProjection[2][2] = 2.0;
    camera.viewProjection[3] = glm::dvec4(-cx / half, -cy / half, -1.0, 1.0);
    return camera;
}

// Seconds until the front changes nothing with no load outstanding (settleFront).
double settle(Front& front, const FrontCamera& camera, const FrontOptions& options) {
    const auto start = Clock::now();
    settleFront(front, camera, options, SettleLimits{INT_MAX, 600.0});
    return secondsSince(start);
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: omh_paging_bench FILE.omh [--budget SIZE | --whole] "
                             "[--views N] [--width PX]\n");
        return 2;
    }
    std::uint64_t budget = defaultMemoryBudget();
    bool whole = false;
    int views = 8;
    double widthPx = 1280.0;
    for (int i = 2; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--whole") {
            whole = true;
        } else if (arg == "--budget" && i + 1 < argc && parseByteSize(argv[i + 1])) {
            budget = *parseByteSize(argv[++i]);
        } else if (arg == "--views" && i + 1 < argc) {
            views = std::max(1, std::atoi(argv[++i]));
        } else if (arg == "--width" && i + 1 < argc) {
            widthPx = std::max(16.0, std::atof(argv[++i]));
        } else {
            std::fprintf(stderr, "omh_paging_bench: unknown or incomplete option '%s'\n",
                         arg.c_str());
            return 2;
        }
    }
    std::string path = argv[1];
    // Any cloud: built and saved first, as `omicron-cli build --save` would.
    const omicron::bench::ScratchPath scratch("omh_paging_bench_", ".omh");
    try {
        if (!isOmhFile(path)) {
            BuildPipeline pipeline;
            pipeline.run(path, PipelineOptions{});
            writeOmh(scratch.path().string(), *pipeline.hierarchy(),
                     omhBuildInfo(pipeline.hierarchyOptions(), pipeline.statistics()));
            path = scratch.path().string();
        }
        const double rawMs = rawReadMs(path);
        const auto start = Clock::now();
        OmhReader reader(path);
        if (!whole) {
            reader.pageOnDemand(budget);
        }
        const auto hierarchy = reader.hierarchy();
        reader.load();
        const double openMs = secondsSince(start) * 1e3;
        const double openRssMb = currentRssMb();

        FrontOptions options;
        options.projectionThresholdPx = 16.0;
        options.pointBudget = 1'000'000;
        options.cpuBudgetMs = 0.0;
        Front front(hierarchy);
        const FrontCamera overview = orthographic(0.5, 0.5, 0.5, widthPx);
        while (front.entries().empty() && secondsSince(start) < 60.0) {
            front.evaluate(overview, options);
            if (front.entries().empty()) {
                std::this_thread::sleep_for(std::chrono::microseconds(100));
            }
        }
        const double firstPixelsMs = secondsSince(start) * 1e3;
        const double overviewMs = settle(front, overview, options) * 1e3;
        const double overviewRssMb = currentRssMb();

        // Close-ups on a grid over the cloud's footprint, a twentieth of the cube wide.
        std::vector<double> detailMs;
        const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(views))));
        for (int v = 0; v < views; ++v) {
            const double cx = (0.5 + v % side) / side;
            const double cy = (0.5 + v / side) / side;
            detailMs.push_back(
                settle(front, orthographic(cx, cy, 0.025, widthPx), options) * 1e3);
        }
        std::sort(detailMs.begin(), detailMs.end());

        std::printf("bench=omh_paging\n");
        std::printf("file=%s\n", argv[1]);
        std::printf("mode=%s\n", whole ? "whole" : "paged");
        std::printf("file_mb=%.1f\n", static_cast<double>(reader.header().fileBytes) / (1 << 20));
        std::printf("points=%llu\n",
                    static_cast<unsigned long long>(reader.header().totalPoints));
        std::printf("raw_read_ms=%.1f\n", rawMs);
        std::printf("open_ms=%.1f\n", openMs);
        std::printf("first_pixels_ms=%.1f\n", firstPixelsMs);
        std::printf("overview_ms=%.1f\n", overviewMs);
        std::printf("view_full_detail_ms_median=%.1f\n", detailMs[detailMs.size() / 2]);
        std::printf("view_full_detail_ms_max=%.1f\n", detailMs.back());
        if (const NodeResidency* residency = hierarchy->residency()) {
            const ResidencyStats stats = residency->stats();
            std::printf("loads=%llu\n", static_cast<unsigned long long>(stats.loads));
            std::printf("evictions=%llu\n", static_cast<unsigned long long>(stats.evictions));
            std::printf("read_mb=%.1f\n", static_cast<double>(stats.bytesRead) / (1 << 20));
            std::printf("resident_mb=%.1f\n", static_cast<double>(stats.residentBytes) / (1 << 20));
            std::printf("budget_mb=%.1f\n", static_cast<double>(stats.budgetBytes) / (1 << 20));
            std::printf("failed_nodes=%llu\n", static_cast<unsigned long long>(stats.failedNodes));
        }
        std::printf("rss_after_open_mb=%.1f\n", openRssMb);
        std::printf("rss_after_overview_mb=%.1f\n", overviewRssMb);
        std::printf("rss_end_mb=%.1f\n", currentRssMb());
        std::printf("peak_rss_mb=%.1f\n", peakRssMb());
    } catch (const std::exception& error) {
        std::fprintf(stderr, "omh_paging_bench: %s\n", error.what());
        return 1;
    }
    return 0;
}
