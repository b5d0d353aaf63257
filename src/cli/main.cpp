// omicron-cli: the headless front end.
#include "command_line.hpp"

#include <array>

int main(int argc, char** argv) {
    using namespace omicron::cli;
    static const std::array<const Command*, 9> commands{
        &infoCommand(),         &generateCommand(), &sortCommand(),
        &exportCommand(),       &buildCommand(),    &convertCommand(),
        &exportPotreeCommand(), &renderCommand(),   &tileCommand()};
    return runCommandLine(commands, argc, argv);
}
