// omicron-cli export: a sorted stream (.oms) as binary PLY, points in stored (Morton) order,
// so any tool can inspect a sorted file.
#include "cli_args.hpp"
#include "commands.hpp"
#include "formats/oms_reader.hpp"
#include "io/ply/ply_writer.hpp"
#include "output_check.hpp"

#include <cstdio>

namespace omicron::cli {

namespace {

int runExport(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, {});
    if (parsed.help) {
        printCommandHelp(exportCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN.oms and OUT.ply, found " +
                         std::to_string(parsed.positionals.size()) + " arguments");
    }
    const std::string& inPath = parsed.positionals[0];
    const std::string& outPath = parsed.positionals[1];
    checkOutputWritable(outPath);
    OmsReader reader(inPath);
    const ReadSummary summary = reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
    const auto cloud = reader.cloud();
    PointBatch points;
    cloud->copyRange(0, cloud->sortedEnd(), points);
    PlyWriteOptions options;
    options.offset = plyStorageOffset(cloud->cube(), cloud->sourceOffset());
    options.comments.push_back("exported by omicron-cli export from " + inPath +
                               " (points in Morton order)");
    writePly(outPath, points, cloud->cube(), options);
    std::printf("exported %llu points from %s to %s\n",
                static_cast<unsigned long long>(summary.pointsDelivered), inPath.c_str(),
                outPath.c_str());
    return 0;
}

} // namespace

const Command& exportCommand() {
    static const Command command{
        "export", "write a sorted stream (.oms) as binary PLY, in stored order",
        "export IN.oms OUT.ply",
        "Reads IN.oms, checking its checksums and Morton order, and writes its points in the\n"
        "stored order as binary little-endian PLY with source coordinates (the .oms source\n"
        "offset becomes a 'comment offset X Y Z' line). OUT is replaced atomically.\n"
        "\n"
        "Exit status: 0 ok, 1 input or output error, 2 usage error.\n",
        runExport};
    return command;
}

} // namespace omicron::cli
