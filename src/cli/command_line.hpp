// The command line of omicron-cli and of omicron-cli-render (which runs `render` for it):
// the first argument names the command; errors become exit statuses.
#pragma once

#include "commands.hpp"

#include <span>

namespace omicron::cli {

// Runs the command argv[1] names among `commands` with the arguments after it, or prints the
// global help. Exit status: 0 ok, 1 input or output error, 2 usage error, 130 interrupted.
int runCommandLine(std::span<const Command* const> commands, int argc, char** argv);

} // namespace omicron::cli
