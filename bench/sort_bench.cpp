// Sorting throughput and the incremental sorter's latency, with baselines from the same run.
//
// usage: sort_bench FILE   (e.g. ../shared/data/autzen_south.ply)
// 1. The file's level-21 (code, index) pairs sorted by our parallel radix sort, by std::sort
//    and by tbb::parallel_sort: Mkeys/s and our speed-up over each (sort only; restoring the
//    unsorted input between runs is not timed).
// 2. The paper's figure 6 for K sort chunks in {1,2,4,8,16,32,64}: read time, time from the
//    end of reading to the first sorted range, and total sort time after reading.
// 3. The sort's page recycling (points/page_recycler.hpp) against giving the input's pages
//    back and faulting the sorted cloud's in: the sort after reading and the minor page faults
//    of the whole sortPointCloud (getrusage), medians of 5 alternating runs each.
//      bench=sort_pages mode=fault|recycle points= sort_after_read_ms= minor_faults=
//      pages_recycled= ... ; then speedup= and faults_ratio= on the recycle line.
#include "bench_timing.hpp"
#include "io/point_reader.hpp"
#include "sort/morton_sorter.hpp"
#include "sort/radix_sort.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <string>
#include <sys/resource.h>
#include <tbb/info.h>
#include <tbb/parallel_sort.h>
#include <vector>

namespace {

using omicron::bench::bestSeconds;
using omicron::bench::quantile;

struct KeyIndex {
    std::uint64_t code;
    std::uint32_t index;
    bool operator<(const KeyIndex& other) const { return code < other.code; }
};

long minorFaults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

// Section 3: the same sort with the input's pages moved into the sorted cloud, and without.
void measurePageRecycling(const std::string& path, std::size_t count) {
    struct Mode {
        const char* name;
        bool recycle;
        std::vector<double> sortMs, faults;
        std::size_t recycled = 0;
    };
    std::array<Mode, 2> modes{Mode{"fault", false, {}, {}}, Mode{"recycle", true, {}, {}}};
    for (int run = 0; run < 5; ++run) {
        for (Mode& mode : modes) {
            auto reader = omicron::openPointCloud(path);
            omicron::SortOptions options;
            options.recyclePages = mode.recycle;
            std::size_t emitted = 0;
            const long faultsBefore = minorFaults();
            const omicron::SortSummary summary = omicron::sortPointCloud(
                *reader, options,
                [&](const omicron::SortedCloud&, std::size_t begin, std::size_t end) {
                    emitted += end - begin;
                });
            if (emitted != count) {
                throw std::runtime_error("sort_bench: a sort emitted " + std::to_string(emitted) +
                                         " of " + std::to_string(count) + " points");
            }
            mode.sortMs.push_back(summary.sortAfterReadSeconds * 1e3);
            mode.recycled = summary.pagesRecycled;
            mode.faults.push_back(static_cast<double>(minorFaults() - faultsBefore));
        }
    }
    const double faultMs = quantile(modes[0].sortMs, 0.5);
    const double faultFaults = quantile(modes[0].faults, 0.5);
    for (const Mode& mode : modes) {
        std::printf("bench=sort_pages mode=%s points=%zu sort_after_read_ms=%.1f minor_faults=%.0f "
                    "pages_recycled=%zu",
                    mode.name, count, quantile(mode.sortMs, 0.5), quantile(mode.faults, 0.5), mode.recycled);
        if (mode.recycle) {
            std::printf(" speedup=%.2f faults_ratio=%.2f", faultMs / quantile(mode.sortMs, 0.5),
                        quantile(mode.faults, 0.5) / faultFaults);
        }
        std::printf("\n");
    }
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: sort_bench FILE\n");
        return 2;
    }
    const std::string path = argv[1];
    try {
        const omicron::LoadedCloud cloud = omicron::loadPointCloud(path);
        const std::size_t count = cloud.points.size();
        std::vector<KeyIndex> input(count);
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3& p = cloud.points.positions[i];
            input[i] = {omicron::morton::encodeUnit(p.x, p.y, p.z), static_cast<std::uint32_t>(i)};
        }
        const int threads = tbb::info::default_concurrency();

        std::vector<KeyIndex> work;
        const auto resetWork = [&] {
            work = input;
        };
        const double stdSortS =
            bestSeconds(3, resetWork, [&] { std::sort(work.begin(), work.end()); });
        const double tbbSortS =
            bestSeconds(3, resetWork, [&] { tbb::parallel_sort(work.begin(), work.end()); });
        std::vector<std::uint64_t> keys(count), keyScratch(count);
        std::vector<std::uint32_t> values(count), valueScratch(count);
        const auto resetKeys = [&] {
            for (std::size_t i = 0; i < count; ++i) {
                keys[i] = input[i].code;
                values[i] = input[i].index;
            }
        };
        const double radixS = bestSeconds(
            3, resetKeys, [&] { omicron::radixSortByKey(keys, values, keyScratch, valueScratch); });
        for (std::size_t i = 0; i < count; ++i) {
            if (keys[i] != work[i].code) {
                std::fprintf(stderr, "sort_bench: radix sort disagrees with tbb::parallel_sort\n");
                return 1;
            }
        }
        const auto line = [&](const char* sorter, double s) {
            std::printf("bench=sort sorter=%s keys=%zu threads=%d ms=%.1f mkeys_per_s=%.1f "
                        "radix_speedup=%.2f\n",
                        sorter, count, threads, s * 1e3, count / s / 1e6, s / radixS);
        };
        line("std_sort", stdSortS);
        line("tbb_parallel_sort", tbbSortS);
        line("omicron_radix", radixS);
        std::fflush(stdout);

        double singleChunkSortS = 0.0;
        for (int chunks : {1, 2, 4, 8, 16, 32, 64}) {
            omicron::SortSummary best;
            best.sortAfterReadSeconds = 1e30;
            for (int run = 0; run < 3; ++run) {
                auto reader = omicron::openPointCloud(path);
                omicron::SortOptions options;
                options.chunks = chunks;
                std::size_t emitted = 0;
                const omicron::SortSummary summary =
                    omicron::sortPointCloud(*reader, options,
                                            [&](const omicron::SortedCloud&, std::size_t begin,
                                                std::size_t end) { emitted += end - begin; });
                if (emitted != count) {
                    std::fprintf(stderr, "sort_bench: %zu of %zu points emitted\n", emitted, count);
                    return 1;
                }
                if (summary.sortAfterReadSeconds < best.sortAfterReadSeconds) {
                    best = summary;
                }
            }
            if (chunks == 1) {
                singleChunkSortS = best.sortAfterReadSeconds;
            }
            std::printf("bench=sort_chunks chunks=%d chunks_used=%d points=%llu read_ms=%.1f "
                        "first_batch_after_read_ms=%.2f sort_after_read_ms=%.1f "
                        "first_batch_vs_single_chunk_sort=%.3f\n",
                        chunks, best.chunksUsed, static_cast<unsigned long long>(best.points),
                        best.readSeconds * 1e3, best.firstRangeAfterReadSeconds * 1e3,
                        best.sortAfterReadSeconds * 1e3,
                        best.firstRangeAfterReadSeconds / singleChunkSortS);
            std::fflush(stdout);
        }
        measurePageRecycling(path, count);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "sort_bench: %s\n", error.what());
        return 1;
    }
    return 0;
}
