// omicron-cli export-potree IN.omh DIR: a saved hierarchy in the Potree 2.0 format, for
// Potree and the tools that read PotreeConverter 2's output.
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/omh_reader.hpp"
#include "formats/potree_writer.hpp"

#include <cstdio>
#include <filesystem>

namespace omicron::cli {

namespace {

int runExportPotree(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, {});
    if (parsed.help) {
        printCommandHelp(exportPotreeCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN.omh and DIR, found " +
                         std::to_string(parsed.positionals.size()) + " arguments");
    }
    const std::string& inPath = parsed.positionals[0];
    const std::string& folder = parsed.positionals[1];
    OmhReader reader(inPath);
    const auto hierarchy = reader.hierarchy();
    reader.load();
    PotreeExportOptions options;
    options.name = std::filesystem::path(inPath).stem().string();
    const PotreeExportSummary summary = exportPotree(*hierarchy, folder, options);
    std::printf("exported %llu nodes, %llu points (%llu hierarchy chunks) from %s to %s\n",
                static_cast<unsigned long long>(summary.nodes),
                static_cast<unsigned long long>(summary.points),
                static_cast<unsigned long long>(summary.chunks), inPath.c_str(), folder.c_str());
    return 0;
}

} // namespace

const Command& exportPotreeCommand() {
    static const Command command{
        "export-potree", "write a saved hierarchy (.omh) in the Potree 2.0 format",
        "export-potree IN.omh DIR",
        "Loads IN.omh (checking every checksum) and writes DIR/metadata.json,\n"
        "DIR/hierarchy.bin and DIR/octree.bin in the Potree 2.0 format, uncompressed\n"
        "(\"DEFAULT\" encoding): the same nodes, each with the points it holds, positions as\n"
        "int32 (2^30 steps of the cube), rgb as uint16 and intensity when present. DIR is\n"
        "created when missing; each file is replaced atomically.\n"
        "\n"
        "Exit status: 0 ok, 1 input or output error, 2 usage error.\n",
        runExportPotree};
    return command;
}

} // namespace omicron::cli
