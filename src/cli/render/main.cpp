// omicron-cli-render: omicron-cli's render command in an executable of its own, so that only
// it loads Qt's GUI and OpenGL libraries. omicron-cli starts it as
// `omicron-cli-render render ARGS...` (render_launcher.cpp).
#include "command_line.hpp"

#include <array>

int main(int argc, char** argv) {
    static const std::array<const omicron::cli::Command*, 1> commands{
        &omicron::cli::renderCommand()};
    return omicron::cli::runCommandLine(commands, argc, argv);
}
