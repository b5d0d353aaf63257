// omicron-cli render runs in omicron-cli-render, installed beside omicron-cli: drawing needs
// Qt's GUI and OpenGL libraries, about 40 of them, and loading them took 26 ms of every start
// of omicron-cli on the test VM (5 ms without them), for the one command that draws.
#include "commands.hpp"
#include "io/atomic_file_writer.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace omicron::cli {

namespace {

// Replaces this process with `omicron-cli-render render ARGS...`: the same arguments,
// output, environment and exit status. Returns only by throwing.
int runInRenderer(const std::vector<std::string>& args) {
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    if (error) {
        throw OutputError("render: cannot find omicron-cli's own folder to start "
                          "omicron-cli-render (/proc/self/exe: " +
                          error.message() + ")");
    }
    const std::filesystem::path renderer = self.parent_path() / "omicron-cli-render";
    std::vector<std::string> words{renderer.string(), "render"};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& word : words) {
        argv.push_back(word.data());
    }
    argv.push_back(nullptr);
    std::fflush(nullptr);
    ::execv(renderer.c_str(), argv.data());
    throw OutputError(renderer.string() + ": cannot start the renderer: " + std::strerror(errno) +
                      " (omicron-cli render runs it, from omicron-cli's own folder)");
}

} // namespace

const Command& renderCommand() {
    static const Command command = renderCommandRunning(runInRenderer);
    return command;
}

} // namespace omicron::cli
