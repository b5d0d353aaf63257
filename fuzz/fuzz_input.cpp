#include "fuzz_input.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace omicron::fuzz {

namespace {

// The process's scratch folder, removed when the process exits normally (the end of a run,
// libFuzzer's -max_total_time); a crash leaves it for the post-mortem.
struct ScratchFolder {
    std::filesystem::path path;

    ScratchFolder() {
        const std::filesystem::path base =
            std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
        path = base / ("omicron-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(path);
    }
    ~ScratchFolder() {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
    ScratchFolder(const ScratchFolder&) = delete;
    ScratchFolder& operator=(const ScratchFolder&) = delete;
};

} // namespace

std::string writeInput(const std::uint8_t* data, std::size_t size, const std::string& name) {
    static const ScratchFolder folder;
    const std::string path = (folder.path / name).string();
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr || (size > 0 && std::fwrite(data, 1, size, file) != size)) {
        throw std::runtime_error("fuzz: cannot write " + path);
    }
    std::fclose(file);
    return path;
}

} // namespace omicron::fuzz
