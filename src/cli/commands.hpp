// omicron-cli's commands. main() dispatches on the first argument and maps exceptions to exit
// statuses: UsageError -> 2, InputError/OutputError -> 1, Interrupted (Ctrl+C) -> 130.
#pragma once

#include <string>
#include <vector>

namespace omicron::cli {

struct Command {
    const char* name;
    const char* summary;                              // one line, for omicron-cli --help
    const char* usage;                                // the synopsis, e.g. "info FILE [--json]"
    const char* help;                                 // the rest of omicron-cli COMMAND --help
    int (*run)(const std::vector<std::string>& args); // exit status; throws on errors
};

const Command& infoCommand();
const Command& generateCommand();
const Command& sortCommand();
const Command& exportCommand();
const Command& buildCommand();
const Command& renderCommand();
const Command& convertCommand();
const Command& exportPotreeCommand();
const Command& tileCommand();

// `render`'s descriptions with `run`: omicron-cli's render command starts omicron-cli-render,
// whose render command renders.
Command renderCommandRunning(int (*run)(const std::vector<std::string>& args));

// Prints "usage: omicron-cli USAGE" and the help text to stdout (for --help).
void printCommandHelp(const Command& command);

} // namespace omicron::cli
