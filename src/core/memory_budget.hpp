// How much memory a pipeline may keep resident, shared by every stage: the sorter sizes its
// runs from it, later stages their caches. Sizes are written as on the command line and in the
// app: "512M", "4G", "1.5GiB", "300000000" (bytes); suffixes are binary (K = 1024).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace omicron {

inline constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
inline constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;

// The smallest budget a pipeline accepts: below it fixed buffers alone would not fit.
inline constexpr std::uint64_t kMinMemoryBudget = 4 * kMiB;

// Bytes for `text`, or nothing when it is not a size (no number, unknown suffix, negative,
// beyond 2^63 bytes).
std::optional<std::uint64_t> parseByteSize(const std::string& text);

// "512 MiB", "4.0 GiB", "812 KiB", "17 B": for messages and fields.
std::string formatByteSize(std::uint64_t bytes);

// The machine's physical memory (sysconf), or 0 when it cannot be told.
std::uint64_t physicalMemoryBytes();

// This process's resident set (Linux: /proc/self/statm), in bytes, and the part of it that
// is file-backed pages (which can be dropped and read again); zeros where it cannot be read.
struct ResidentSet {
    std::uint64_t bytes = 0;
    std::uint64_t fileBackedBytes = 0;
};
ResidentSet processResidentSet();

// The default budget: half of physical memory (4 GiB when it cannot be told), so small clouds
// never spill and a big one leaves the rest of the machine usable.
std::uint64_t defaultMemoryBudget();

} // namespace omicron
