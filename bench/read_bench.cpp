// Reader throughput: each reader vs a raw read() of the same bytes, measured in the same run
// with the page cache warm, so the ratio shows parsing cost rather than disk speed.
//
// usage: read_bench FILE [--keep-temp]   (--keep-temp: the converted files stay, in a folder it
//                                          names; see bench_scratch.hpp)
//        read_bench --laz FILE.laz [SAME_POINTS.las] [--laz-perf NODE_MODULES_DIR]
// FILE is read as it is; then the same points are written as binary big-endian PLY, ascii PLY,
// LAS 1.4 (point format 7) and XYZ text in a temporary folder and each is measured too.
// --laz measures the LAZ reader with 1 and 2 oneTBB threads: phase=decode (chunks to LAS
// records only) and phase=read (points delivered, as any reader), against reading the same
// points uncompressed (phase=read of the LAS file, one thread) and, with --laz-perf, against the
// npm laz-perf decoder (WebAssembly, run by node on the same file; bench/laz_perf_decode.js):
//   bench=read reader=laz phase=decode threads=2 points=... mpoints_per_s=...
//   speedup_vs_1_thread=... las_mpoints_per_s=... ratio_vs_las=... ratio_vs_laz_perf=...
// One line per reader and phase:
//   bench=read reader=ply_binary_little_endian phase=parse points=... mpoints_per_s=...
//   mb_per_s=... raw_mb_per_s=... ratio_vs_raw=...
// phase=open_and_read includes the bounds pre-pass of formats whose header has no bounds;
// phase=parse passes the bounds in (OpenOptions::knownBounds), so it is the streaming parse.
// The same points sorted into a .oms (pipeline 2's input) are measured too, reader=oms
// phase=parse: OmsReader streaming the records into its cloud, each range's codes recomputed
// and checked for order, and the payload checksum (a FILE that is a .oms is measured alone).
#include "bench_scratch.hpp"
#include "bench_timing.hpp"
#include "formats/oms_reader.hpp"
#include "formats/oms_writer.hpp"
#include "io/file_stream.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_writer.hpp"
#include "io/laz/laz_records.hpp"
#include "io/ply/ply_writer.hpp"
#include "io/point_reader.hpp"
#include "io/xyz/xyz_writer.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <string>
#include <tbb/global_control.h>
#include <unistd.h>
#include <vector>

namespace {

using omicron::bench::bestSeconds;

std::uint64_t rawRead(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) {
        std::perror(path.c_str());
        std::exit(1);
    }
    std::vector<char> block(4 << 20);
    std::uint64_t total = 0;
    for (;;) {
        const ssize_t got = ::read(fd, block.data(), block.size());
        if (got <= 0) {
            break;
        }
        total += static_cast<std::uint64_t>(got);
    }
    ::close(fd);
    return total;
}

std::uint64_t readAll(const std::string& path, const omicron::OpenOptions& options) {
    auto reader = omicron::openPointCloud(path, options);
    std::uint64_t points = 0;
    reader->read([&](const omicron::PointBatch& batch) { points += batch.size(); });
    return points;
}

// One bench=read line: `seconds` to deliver `points` from a file of `bytes`, against
// `rawSeconds` to read those bytes.
void printRead(const std::string& label, const char* phase, std::uint64_t points,
               std::uint64_t bytes, double seconds, double rawSeconds) {
    std::printf("bench=read reader=%s phase=%s points=%llu bytes=%llu bytes_per_point=%.1f "
                "ms=%.1f mpoints_per_s=%.2f mb_per_s=%.1f raw_mb_per_s=%.1f ratio_vs_raw=%.3f\n",
                label.c_str(), phase, static_cast<unsigned long long>(points),
                static_cast<unsigned long long>(bytes), double(bytes) / double(points),
                seconds * 1e3, points / seconds / 1e6, bytes / seconds / 1e6,
                bytes / rawSeconds / 1e6, rawSeconds / seconds);
    std::fflush(stdout);
}

// The best of `runs` raw reads of `path`, the page cache warmed first.
double rawReadSeconds(const std::string& path, int runs) {
    rawRead(path);
    return bestSeconds(runs, [&] { rawRead(path); });
}

void measure(const std::string& label, const std::string& path, int runs) {
    const std::uint64_t bytes = std::filesystem::file_size(path);
    const double rawS = rawReadSeconds(path, runs);
    std::uint64_t points = 0;
    const double fullS = bestSeconds(runs, [&] { points = readAll(path, {}); });
    const omicron::Bounds bounds = omicron::openPointCloud(path)->info().sourceBounds;
    omicron::OpenOptions known;
    known.knownBounds = bounds;
    const double parseS = bestSeconds(runs, [&] { readAll(path, known); });
    printRead(label, "open_and_read", points, bytes, fullS, rawS);
    printRead(label, "parse", points, bytes, parseS, rawS);
}

// A .oms into its sorted cloud, as `build IN.oms` reads it (without the builder).
void measureOms(const std::string& path, int runs) {
    const std::uint64_t bytes = std::filesystem::file_size(path);
    const double rawS = rawReadSeconds(path, runs);
    std::uint64_t points = 0;
    const double parseS = bestSeconds(runs, [&] {
        omicron::OmsReader reader(path);
        points = 0;
        reader.read([&](const omicron::SortedCloud&, std::size_t begin, std::size_t end) {
            points += end - begin;
        });
    });
    printRead("oms", "parse", points, bytes, parseS, rawS);
}

// Sorts `input` into `oms` (pipeline 1; the cloud is written once sorted).
void sortInto(const std::string& input, const std::string& oms) {
    auto reader = omicron::openPointCloud(input);
    std::shared_ptr<const omicron::SortedCloud> cloud;
    const omicron::SortSummary sorted = omicron::sortPointCloud(
        *reader, omicron::SortOptions{},
        [](const omicron::SortedCloud&, std::size_t, std::size_t) {},
        [&](const omicron::IncrementalMortonSorter& sorter) { cloud = sorter.cloud(); });
    omicron::writeOms(oms, *cloud, sorted.points);
}

std::string label(omicron::CloudFormat format) {
    switch (format) {
    case omicron::CloudFormat::PlyAscii:
        return "ply_ascii";
    case omicron::CloudFormat::PlyBinaryLittleEndian:
        return "ply_binary_little_endian";
    case omicron::CloudFormat::PlyBinaryBigEndian:
        return "ply_binary_big_endian";
    case omicron::CloudFormat::Las:
        return "las";
    case omicron::CloudFormat::Laz:
        return "laz";
    case omicron::CloudFormat::Xyz:
        return "xyz";
    }
    return "unknown";
}

// LAZ chunks to LAS records, nothing else: the decoder's own speed.
std::uint64_t decodeLazRecords(const std::string& path) {
    auto stream = std::make_unique<omicron::FileStream>(path);
    const omicron::las::Header header = omicron::las::readHeader(*stream);
    auto records = omicron::openLazRecords(std::move(stream), header);
    std::uint64_t points = 0;
    records->forEachBlock([&](const omicron::LasRecordBlock& block) {
        points += block.count;
        return true;
    });
    return points;
}

// Runs bench/laz_perf_decode.js on `laz`; prints its line and returns its points/s (0 when it
// cannot run: no node, no laz-perf in `nodeModules`).
double lazPerfPointsPerS(const std::string& nodeModules, const std::string& laz) {
    const auto quoted = [](const std::string& text) {
        std::string out = "'";
        for (const char c : text) {
            out += c == '\'' ? std::string("'\\''") : std::string(1, c);
        }
        return out + "'";
    };
    const std::string command = "node " + quoted(OMICRON_BENCH_DIR "/laz_perf_decode.js") + " " +
                                quoted(nodeModules) + " " + quoted(laz);
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) {
        return 0;
    }
    char line[512] = {};
    const bool got = std::fgets(line, sizeof line, pipe) != nullptr;
    const int status = ::pclose(pipe);
    const char* rate = got ? std::strstr(line, "mpoints_per_s=") : nullptr;
    if (status != 0 || rate == nullptr) {
        std::fprintf(stderr, "read_bench: laz-perf did not run (%s)\n", command.c_str());
        return 0;
    }
    std::printf("%s", line);
    std::fflush(stdout);
    return std::atof(rate + std::strlen("mpoints_per_s=")) * 1e6;
}

void printLaz(const char* phase, int threads, std::uint64_t points, double seconds,
              double oneThreadSeconds, double lasPointsPerS, double lazPerfPointsPerS) {
    const double pointsPerS = points / seconds;
    std::printf("bench=read reader=laz phase=%s threads=%d points=%llu ms=%.1f "
                "mpoints_per_s=%.2f speedup_vs_1_thread=%.2f",
                phase, threads, static_cast<unsigned long long>(points), seconds * 1e3,
                pointsPerS / 1e6, oneThreadSeconds / seconds);
    if (lasPointsPerS > 0) {
        std::printf(" las_mpoints_per_s=%.2f ratio_vs_las=%.3f", lasPointsPerS / 1e6,
                    pointsPerS / lasPointsPerS);
    }
    if (lazPerfPointsPerS > 0) {
        std::printf(" laz_perf_mpoints_per_s=%.2f ratio_vs_laz_perf=%.2f", lazPerfPointsPerS / 1e6,
                    pointsPerS / lazPerfPointsPerS);
    }
    std::printf("\n");
    std::fflush(stdout);
}

int measureLaz(const std::string& laz, const std::string& las, const std::string& lazPerf) {
    rawRead(laz); // warm the page cache
    const double lazPerfRate = lazPerf.empty() ? 0 : lazPerfPointsPerS(lazPerf, laz);
    double lasPointsPerS = 0;
    if (!las.empty()) {
        rawRead(las);
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        std::uint64_t points = 0;
        const double seconds = bestSeconds(3, [&] { points = readAll(las, {}); });
        lasPointsPerS = points / seconds;
        std::printf("bench=read reader=las phase=read threads=1 points=%llu ms=%.1f "
                    "mpoints_per_s=%.2f\n",
                    static_cast<unsigned long long>(points), seconds * 1e3, lasPointsPerS / 1e6);
    }
    double oneThreadDecode = 0;
    double oneThreadRead = 0;
    for (const int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                  static_cast<std::size_t>(threads));
        std::uint64_t points = 0;
        const double decode = bestSeconds(3, [&] { points = decodeLazRecords(laz); });
        const double read = bestSeconds(3, [&] { points = readAll(laz, {}); });
        if (threads == 1) {
            oneThreadDecode = decode;
            oneThreadRead = read;
        }
        printLaz("decode", threads, points, decode, oneThreadDecode, lasPointsPerS, lazPerfRate);
        printLaz("read", threads, points, read, oneThreadRead, lasPointsPerS, lazPerfRate);
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: read_bench FILE [--keep-temp]\n"
                             "       read_bench --laz FILE.laz [SAME_POINTS.las] "
                             "[--laz-perf NODE_MODULES_DIR]\n");
        return 2;
    }
    if (std::strcmp(argv[1], "--laz") == 0) {
        std::string laz;
        std::string las;
        std::string lazPerf;
        for (int i = 2; i < argc; ++i) {
            if (std::strcmp(argv[i], "--laz-perf") == 0 && i + 1 < argc) {
                lazPerf = argv[++i];
            } else if (laz.empty()) {
                laz = argv[i];
            } else {
                las = argv[i];
            }
        }
        if (laz.empty()) {
            std::fprintf(stderr, "usage: read_bench --laz FILE.laz [SAME_POINTS.las] "
                                 "[--laz-perf NODE_MODULES_DIR]\n");
            return 2;
        }
        try {
            return measureLaz(laz, las, lazPerf);
        } catch (const std::exception& error) {
            std::fprintf(stderr, "read_bench: %s\n", error.what());
            return 1;
        }
    }
    const std::string input = argv[1];
    const bool keepTemp = argc > 2 && std::strcmp(argv[2], "--keep-temp") == 0;
    try {
        if (omicron::isOmsFile(input)) {
            measureOms(input, 3);
            return 0;
        }
        measure(label(omicron::detectFormat(input)), input, 3);

        const omicron::LoadedCloud cloud = omicron::loadPointCloud(input);
        omicron::bench::ScratchPath scratch("omicron-read-bench-");
        if (keepTemp) {
            scratch.keep();
        }
        const std::filesystem::path& folder = scratch.path();
        std::filesystem::create_directories(folder);
        const auto file = [&](const char* name) {
            return (folder / name).string();
        };

        omicron::PlyWriteOptions bigEndian;
        bigEndian.encoding = omicron::PlyEncoding::BinaryBigEndian;
        bigEndian.offset = omicron::plyStorageOffset(cloud.info.cube, cloud.info.sourceOffset);
        omicron::writePly(file("big_endian.ply"), cloud.points, cloud.info.cube, bigEndian);
        omicron::PlyWriteOptions ascii = bigEndian;
        ascii.encoding = omicron::PlyEncoding::Ascii;
        omicron::writePly(file("ascii.ply"), cloud.points, cloud.info.cube, ascii);
        omicron::LasWriteOptions las;
        las.versionMinor = 4;
        las.pointFormat = 7;
        las.scale = glm::dvec3(0.001);
        las.offset = cloud.info.sourceOffset;
        omicron::writeLas(file("cloud.las"), cloud.points, cloud.info.cube, las);
        omicron::writeXyz(file("cloud.xyz"), cloud.points, cloud.info.cube,
                          cloud.info.sourceOffset);

        for (const char* name : {"big_endian.ply", "cloud.las", "ascii.ply", "cloud.xyz"}) {
            measure(label(omicron::detectFormat(file(name))), file(name), 2);
        }
        sortInto(input, file("cloud.oms"));
        measureOms(file("cloud.oms"), 2);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "read_bench: %s\n", error.what());
        return 1;
    }
    return 0;
}
