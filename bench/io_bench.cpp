// io_bench: the paper's pipelines 2 and 3 on one cloud. File sizes of the sorted stream
// (.oms) against the saved hierarchy (.omh, leaf collapse off and paper), the time to a
// complete hierarchy in memory from each (pipeline 2 rebuilds it from the sorted points,
// pipeline 3 only loads it), and the time until level 0 is available from a .omh, when a
// viewer can draw its first overview.
//
// usage: io_bench FILE [--depth D]   (e.g. ../shared/data/autzen_south.ply, depth 7)
// The files go to a fresh temporary folder, removed at the end (bench_scratch.hpp). Every time
// is the best of 3 runs from files the page cache holds (what a second session sees).
#include "bench_scratch.hpp"
#include "bench_timing.hpp"
#include "build/hierarchy_builder.hpp"
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "formats/oms_reader.hpp"
#include "formats/oms_writer.hpp"
#include "io/point_reader.hpp"
#include "sort/morton_sorter.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

namespace {

using omicron::bench::bestSeconds;
using omicron::bench::Clock;
using omicron::bench::secondsSince;

constexpr int kRuns = 3;

// Pipeline 2: .oms streamed into the builder until the hierarchy is complete.
std::unique_ptr<omicron::HierarchyBuilder> buildFromOms(const std::string& path,
                                                        const omicron::BuildOptions& options) {
    omicron::OmsReader reader(path);
    auto builder = std::make_unique<omicron::HierarchyBuilder>(reader.cloud(), options);
    reader.read(builder->consumer());
    builder->finish();
    builder->wait();
    return builder;
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: io_bench FILE [--depth D]\n");
        return 2;
    }
    int depth = 7;
    if (argc > 3 && std::strcmp(argv[2], "--depth") == 0) {
        depth = std::atoi(argv[3]);
    }
    namespace fs = std::filesystem;
    const omicron::bench::ScratchPath scratch("io_bench-");
    const fs::path& folder = scratch.path();
    try {
        fs::create_directories(folder);
        const std::string omsPath = (folder / "cloud.oms").string();
        const std::string omhOffPath = (folder / "off.omh").string();
        const std::string omhPaperPath = (folder / "paper.omh").string();

        // Pipeline 1 once, to make the .oms.
        {
            auto reader = omicron::openPointCloud(argv[1]);
            omicron::OmsWriter writer;
            omicron::sortPointCloud(*reader, omicron::SortOptions{},
                                    [&](const omicron::SortedCloud& cloud, std::size_t begin,
                                        std::size_t end) {
                                        if (begin == 0) {
                                            writer.open(omsPath, cloud.cube(), cloud.sourceOffset(),
                                                        cloud.attributes(), cloud.capacity());
                                        }
                                        writer.append(cloud, begin, end);
                                    });
            writer.finish();
        }

        omicron::BuildOptions off;
        off.maxLevel = depth;
        omicron::BuildOptions paper = off;
        paper.collapse = omicron::LeafCollapse::Paper;
        std::uint64_t points = 0, nodes = 0;
        const double omsSeconds = bestSeconds(kRuns, [&] {
            const auto builder = buildFromOms(omsPath, off);
            points = builder->statistics().inputPoints;
            nodes = builder->statistics().totalNodes();
        });
        double saveSeconds = 0.0;
        for (const auto& [options, path] : {std::pair{off, omhOffPath}, std::pair{paper, omhPaperPath}}) {
            const auto builder = buildFromOms(omsPath, options);
            const auto start = Clock::now();
            omicron::writeOmh(path, builder->hierarchy(),
                              omicron::omhBuildInfo(options, builder->statistics()));
            if (options.collapse == omicron::LeafCollapse::Off) {
                saveSeconds = secondsSince(start);
            }
        }

        double firstLevelSeconds = 1e30;
        const double omhSeconds = bestSeconds(kRuns, [&] {
            const auto start = Clock::now();
            omicron::OmhReader reader(omhOffPath);
            const auto hierarchy = reader.hierarchy();
            reader.load([&](int level) {
                if (level == 0) {
                    firstLevelSeconds = std::min(firstLevelSeconds, secondsSince(start));
                }
            });
        });
        const double verifySeconds = bestSeconds(kRuns, [&] {
            omicron::OmhReader reader(omhOffPath);
            reader.verify();
        });

        const auto omsBytes = fs::file_size(omsPath);
        const auto offBytes = fs::file_size(omhOffPath);
        const auto paperBytes = fs::file_size(omhPaperPath);
        std::printf("bench=io_sizes points=%llu depth=%d nodes=%llu oms_bytes=%llu "
                    "omh_off_bytes=%llu omh_paper_bytes=%llu omh_off_per_oms=%.3f "
                    "omh_paper_per_oms=%.3f\n",
                    static_cast<unsigned long long>(points), depth,
                    static_cast<unsigned long long>(nodes),
                    static_cast<unsigned long long>(omsBytes),
                    static_cast<unsigned long long>(offBytes),
                    static_cast<unsigned long long>(paperBytes), double(offBytes) / omsBytes,
                    double(paperBytes) / omsBytes);
        std::printf("bench=io_hierarchy pipeline2_oms_to_hierarchy_ms=%.1f "
                    "pipeline3_omh_to_hierarchy_ms=%.1f speedup=%.2f "
                    "omh_first_level_ms=%.2f omh_save_ms=%.1f omh_verify_ms=%.1f\n",
                    omsSeconds * 1e3, omhSeconds * 1e3, omsSeconds / omhSeconds,
                    firstLevelSeconds * 1e3, saveSeconds * 1e3, verifySeconds * 1e3);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "io_bench: %s\n", error.what());
        return 1;
    }
    return 0;
}
