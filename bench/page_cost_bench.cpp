// What fresh memory costs on this machine: the floor under the kernel time of any stage that
// fills memory it has not touched before (the sorter's arrival arrays, the sorted cloud, the
// .omh written to a tmpfs). Each figure is set against the same bytes written into memory
// that is already there, measured in the same run:
//
//   anonymous    mmap'd memory touched for the first time, page by page (a fault each)
//   populated    the same after madvise(MADV_POPULATE_WRITE): the faults taken in one call
//   rewritten    the same memory written again (the baseline: no fault, no new page)
//   file_new     pwrite of the bytes to a new file in DIR (a tmpfs: new page-cache pages)
//   file_again   pwrite of the same bytes over that file's existing pages (the baseline)
//
// usage: page_cost_bench [--mib N] [--dir DIR]   (default 1024 MiB in /dev/shm)
//        page_cost_bench --mib N --populate-only   (maps N MiB, populates them in one call and
//                                                   exits: bench/kernel_floor.sh times it as a
//                                                   whole process, the floor of a peak resident
//                                                   set of N MiB)
// Lines: bench=page_cost case=... mib= ms= ns_per_page= gb_per_s= minor_faults=
//        bench=page_cost summary fresh_anonymous_s_per_gb= fresh_file_s_per_gb= ...
#include "bench_timing.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <string>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

namespace {

using omicron::bench::Clock;
using omicron::bench::secondsSince;

constexpr std::size_t kPage = 4096;

long minorFaults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

struct Figure {
    double seconds = 0.0;
    long faults = 0;
};

void print(const char* name, std::size_t bytes, const Figure& figure) {
    const double pages = static_cast<double>(bytes / kPage);
    std::printf("bench=page_cost case=%s mib=%zu ms=%.1f ns_per_page=%.0f gb_per_s=%.2f "
                "minor_faults=%ld\n",
                name, bytes >> 20, figure.seconds * 1e3, figure.seconds * 1e9 / pages,
                static_cast<double>(bytes) / figure.seconds / 1e9, figure.faults);
}

void* mapAnonymous(std::size_t bytes) {
    void* memory = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (memory == MAP_FAILED) {
        std::fprintf(stderr, "page_cost_bench: mmap of %zu bytes failed: %s\n", bytes,
                     std::strerror(errno));
        std::exit(1);
    }
    // Small pages: what a fresh page costs one fault at a time (huge pages are the policy's
    // other side, points/huge_page_policy.hpp; see README, "Huge pages").
    madvise(memory, bytes, MADV_NOHUGEPAGE);
    return memory;
}

// Faults in [memory, memory + bytes) with one MADV_POPULATE_WRITE; false (said on stderr) when
// the kernel refuses.
bool populate(void* memory, std::size_t bytes) {
    if (madvise(memory, bytes, MADV_POPULATE_WRITE) != 0) {
        std::fprintf(stderr, "page_cost_bench: MADV_POPULATE_WRITE: %s\n", std::strerror(errno));
        return false;
    }
    return true;
}

// Writes `bytes` of `source` into fresh anonymous memory, optionally populated first.
Figure fillFresh(const std::uint8_t* source, std::size_t bytes, bool populateFirst) {
    const long faultsBefore = minorFaults();
    const auto start = Clock::now();
    auto* memory = static_cast<std::uint8_t*>(mapAnonymous(bytes));
    if (populateFirst) {
        populate(memory, bytes);
    }
    std::memcpy(memory, source, bytes);
    Figure figure{secondsSince(start), minorFaults() - faultsBefore};
    munmap(memory, bytes);
    return figure;
}

void writeAll(int fd, const std::uint8_t* data, std::size_t bytes, const std::string& path) {
    for (std::size_t done = 0; done < bytes;) {
        const ssize_t written = pwrite(fd, data + done, bytes - done, static_cast<off_t>(done));
        if (written < 0 && errno == EINTR) {
            continue;
        }
        if (written <= 0) {
            std::fprintf(stderr, "page_cost_bench: writing %s: %s\n", path.c_str(),
                         std::strerror(errno));
            std::exit(1);
        }
        done += static_cast<std::size_t>(written);
    }
}

} // namespace

int main(int argc, char** argv) {
    std::size_t mib = 1024;
    std::string dir = "/dev/shm";
    bool populateOnly = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--mib" && i + 1 < argc) {
            mib = std::strtoull(argv[++i], nullptr, 10);
        } else if (arg == "--dir" && i + 1 < argc) {
            dir = argv[++i];
        } else if (arg == "--populate-only") {
            populateOnly = true;
        } else {
            std::fprintf(
                stderr, "usage: page_cost_bench [--mib N] [--dir DIR] | --mib N --populate-only\n");
            return 2;
        }
    }
    if (mib == 0) {
        std::fprintf(stderr, "page_cost_bench: --mib must be at least 1\n");
        return 2;
    }
    const std::size_t bytes = mib << 20;
    if (populateOnly) {
        const long faultsBefore = minorFaults();
        const auto start = Clock::now();
        void* memory = mapAnonymous(bytes);
        if (!populate(memory, bytes)) {
            return 1;
        }
        print("populate_only", bytes, {secondsSince(start), minorFaults() - faultsBefore});
        munmap(memory, bytes);
        return 0;
    }

    // The source: faulted in and filled once, outside every timing.
    auto* source = static_cast<std::uint8_t*>(mapAnonymous(bytes));
    for (std::size_t i = 0; i < bytes; ++i) {
        source[i] = static_cast<std::uint8_t>(i * 131u);
    }

    const Figure anonymous = fillFresh(source, bytes, false);
    const Figure populated = fillFresh(source, bytes, true);
    Figure rewritten;
    {
        auto* memory = static_cast<std::uint8_t*>(mapAnonymous(bytes));
        std::memcpy(memory, source, bytes); // faulted in, untimed
        const long faultsBefore = minorFaults();
        const auto start = Clock::now();
        std::memcpy(memory, source + 1, bytes - 1); // other bytes, same pages
        rewritten = {secondsSince(start), minorFaults() - faultsBefore};
        munmap(memory, bytes);
    }

    const std::string path = dir + "/page_cost_bench." + std::to_string(getpid());
    const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
    if (fd < 0) {
        std::fprintf(stderr, "page_cost_bench: cannot create %s: %s\n", path.c_str(),
                     std::strerror(errno));
        return 1;
    }
    unlink(path.c_str()); // removed however the run ends; the descriptor keeps it
    Figure fileNew, fileAgain;
    {
        const auto start = Clock::now();
        writeAll(fd, source, bytes, path);
        fileNew.seconds = secondsSince(start);
    }
    {
        const auto start = Clock::now();
        writeAll(fd, source, bytes, path);
        fileAgain.seconds = secondsSince(start);
    }
    close(fd);

    print("anonymous", bytes, anonymous);
    print("populated", bytes, populated);
    print("rewritten", bytes, rewritten);
    print("file_new", bytes, fileNew);
    print("file_again", bytes, fileAgain);
    const double gb = static_cast<double>(bytes) / 1e9;
    std::printf("bench=page_cost summary mib=%zu dir=%s fresh_anonymous_s_per_gb=%.3f "
                "rewritten_s_per_gb=%.3f fresh_vs_rewritten=%.1f fresh_file_s_per_gb=%.3f "
                "file_again_s_per_gb=%.3f file_new_vs_again=%.1f\n",
                mib, dir.c_str(), anonymous.seconds / gb, rewritten.seconds / gb,
                anonymous.seconds / rewritten.seconds, fileNew.seconds / gb, fileAgain.seconds / gb,
                fileNew.seconds / fileAgain.seconds);
    munmap(source, bytes);
    return 0;
}
