#include "points/huge_page_policy.hpp"

#include "points/huge_page_buffer.hpp"

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sys/mman.h>

namespace omicron {

namespace {

constexpr const char* kPageReportingParameters = "/sys/module/page_reporting/parameters";
constexpr const char* kTransparentHugePages = "/sys/kernel/mm/transparent_hugepage/enabled";

// The selected mode is the bracketed word: "always [madvise] never".
bool transparentHugePagesOff() {
    std::ifstream modes(kTransparentHugePages);
    std::string line;
    return !std::getline(modes, line) || line.find("[never]") != std::string::npos;
}

// Seconds to write one byte per small page of `bytes` fresh bytes advised `advice`, at an
// address aligned to 2 MiB so that a huge page can back each 2 MiB; infinite if nothing could
// be mapped.
double secondsToFirstTouch(std::size_t bytes, int advice) {
    const std::size_t mapped = bytes + kHugePageBytes;
    void* memory = mmap(nullptr, mapped, PROT_READ | PROT_WRITE,
                        MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (memory == MAP_FAILED) {
        return std::numeric_limits<double>::infinity();
    }
    adviseWholePages(memory, mapped, kHugePageBytes, advice);
    auto* aligned =
        reinterpret_cast<volatile std::byte*>(wholePages(memory, mapped, kHugePageBytes).first);
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t at = 0; at < bytes; at += kSmallPageBytes) {
        aligned[at] = std::byte{1};
    }
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    munmap(memory, mapped);
    return took.count();
}

} // namespace

FirstTouchCost measureFirstTouchCost() {
    constexpr double kMiB = 1 << 20;
    FirstTouchCost cost;
    cost.smallSecondsPerMiB =
        secondsToFirstTouch(kHugePageBytes, MADV_NOHUGEPAGE) / (kHugePageBytes / kMiB);
    cost.hugeSecondsPerMiB =
        transparentHugePagesOff()
            ? std::numeric_limits<double>::infinity()
            : secondsToFirstTouch(2 * kHugePageBytes, MADV_HUGEPAGE) / (2 * kHugePageBytes / kMiB);
    return cost;
}

bool hugePagesPayOff(const std::optional<std::string>& override,
                     const std::string& pageReportingParameters,
                     const std::function<FirstTouchCost()>& measure) {
    if (override == "0") {
        return false;
    }
    if (override == "1") {
        return true;
    }
    std::ifstream reported(pageReportingParameters + "/reported_kib");
    unsigned long long kib = 0;
    if (!(reported >> kib) || kib == 0) {
        return true;
    }
    const FirstTouchCost cost = measure();
    return cost.hugeSecondsPerMiB < cost.smallSecondsPerMiB;
}

bool hugePagesPayOff() {
    static const bool payOff = [] {
        const char* value = std::getenv("OMICRON_HUGE_PAGES");
        return hugePagesPayOff(value ? std::optional<std::string>(value) : std::nullopt,
                               kPageReportingParameters, measureFirstTouchCost);
    }();
    return payOff;
}

} // namespace omicron
