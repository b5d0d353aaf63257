#include "process_memory.hpp"

#include <cstdio>
#include <unistd.h>

namespace omicron {

std::size_t residentBytes() {
    std::FILE* file = std::fopen("/proc/self/statm", "r");
    if (file == nullptr) {
        return 0;
    }
    unsigned long long totalPages = 0;
    unsigned long long residentPages = 0;
    const int fields = std::fscanf(file, "%llu %llu", &totalPages, &residentPages);
    std::fclose(file);
    const long pageBytes = sysconf(_SC_PAGESIZE);
    if (fields != 2 || pageBytes <= 0) {
        return 0;
    }
    return static_cast<std::size_t>(residentPages) * static_cast<std::size_t>(pageBytes);
}

} // namespace omicron
