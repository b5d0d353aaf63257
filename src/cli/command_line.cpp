// Dispatches omicron-cli's command line to a command and turns errors into exit statuses:
// 0 ok, 1 input or output error, 2 usage error, 130 interrupted.
#include "command_line.hpp"

#include "cli_args.hpp"
#include "interrupt.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/input_error.hpp"

#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

namespace {

using omicron::cli::Command;

constexpr int kExitInputOutput = 1;
constexpr int kExitUsage = 2;
constexpr int kExitInterrupted = 130; // 128 + SIGINT, as shells report it

void printGlobalHelp(std::span<const Command* const> commands) {
    std::printf("usage: omicron-cli COMMAND [OPTIONS] [ARGS]\n\ncommands:\n");
    for (const Command* command : commands) {
        std::printf("  %-14s %s\n", command->name, command->summary);
    }
    std::printf("\n'omicron-cli COMMAND --help' describes a command.\n"
                "Exit status: 0 ok, 1 input or output error, 2 usage error, 130 interrupted.\n");
}

int usageFailure(const std::string& reason, const Command* command) {
    std::fprintf(stderr, "omicron-cli: %s\n", reason.c_str());
    if (command != nullptr) {
        std::fprintf(stderr, "usage: omicron-cli %s (see 'omicron-cli %s --help')\n",
                     command->usage, command->name);
    } else {
        std::fprintf(stderr, "see 'omicron-cli --help'\n");
    }
    return kExitUsage;
}

} // namespace

namespace omicron::cli {

void printCommandHelp(const Command& command) {
    std::printf("usage: omicron-cli %s\n\n%s", command.usage, command.help);
}

int runCommandLine(std::span<const Command* const> commands, int argc, char** argv) {
    const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
    if (args.empty()) {
        return usageFailure("missing COMMAND", nullptr);
    }
    const std::string& name = args[0];
    if (name == "--help" || name == "-h" || name == "help") {
        printGlobalHelp(commands);
        return 0;
    }
    const Command* command = nullptr;
    for (const Command* candidate : commands) {
        if (name == candidate->name) {
            command = candidate;
        }
    }
    if (command == nullptr) {
        return usageFailure("unknown command '" + name + "'", nullptr);
    }
    try {
        return command->run(std::vector<std::string>(args.begin() + 1, args.end()));
    } catch (const omicron::cli::Interrupted&) {
        std::fprintf(stderr, "omicron-cli: %s: interrupted; no output was written\n",
                     command->name);
        return kExitInterrupted;
    } catch (const omicron::cli::UsageError& error) {
        return usageFailure(std::string(command->name) + ": " + error.what(), command);
    } catch (const omicron::InputError& error) {
        std::fprintf(stderr, "omicron-cli: %s\n", error.what());
    } catch (const omicron::OutputError& error) {
        std::fprintf(stderr, "omicron-cli: %s\n", error.what());
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "omicron-cli: out of memory\n");
    } catch (const std::exception& error) { // e.g. a filesystem error after writing
        std::fprintf(stderr, "omicron-cli: %s\n", error.what());
    }
    return kExitInputOutput;
}

} // namespace omicron::cli
