// Resident memory of this process, for the status bar and the memory chart.
#pragma once

#include <cstddef>

namespace omicron {

// Resident set size in bytes (Linux: /proc/self/statm); 0 where it cannot be read.
std::size_t residentBytes();

} // namespace omicron
