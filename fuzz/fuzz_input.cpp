#include "fuzz_input.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace omicron::fuzz {

std::string writeInput(const std::uint8_t* data, std::size_t size, const std::string& name) {
    static const std::filesystem::path folder = [] {
        const std::filesystem::path base =
            std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
        const auto path = base / ("omicron-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(path);
        return path;
    }();
    const std::string path = (folder / name).string();
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr || (size > 0 && std::fwrite(data, 1, size, file) != size)) {
        throw std::runtime_error("fuzz: cannot write " + path);
    }
    std::fclose(file);
    return path;
}

} // namespace omicron::fuzz
