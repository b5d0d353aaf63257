// Command-line parsing for omicron-cli's commands: "--name value", "--name=value", flags,
// positional arguments and "--" (everything after it is positional).
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace omicron::cli {

// A mistake on the command line: main prints it with a usage hint and exits with status 2.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct OptionSpec {
    std::string name; // without the leading "--"
    bool takesValue = false;
};

class ParsedArgs {
public:
    bool help = false; // --help or -h was given: print the command's help, ignore the rest
    std::vector<std::string> positionals;

    bool flag(std::string_view name) const;
    std::optional<std::string> value(std::string_view name) const;

    // Records an option; a repeated option keeps its last value.
    void set(const std::string& name, std::string value);

private:
    std::vector<std::pair<std::string, std::string>> m_options;
};

// Throws UsageError for an unknown option or an option without its value.
ParsedArgs parseArgs(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs);

// A decimal integer in [min, max] given to `--option`; throws UsageError naming the option.
std::uint64_t parseInteger(const std::string& text, const std::string& option, std::uint64_t min,
                           std::uint64_t max);

// --threads T: worker threads, 1..1024, all cores when absent (sort and build share it).
int threadsOption(const ParsedArgs& parsed);

// --chunks K: sort chunks, 1..kMaxSortChunks, kDefaultSortChunks when absent.
int sortChunksOption(const ParsedArgs& parsed);

// --memory-budget SIZE and --temp-dir DIR, for every command that sorts a cloud.
inline const std::vector<OptionSpec> kMemoryOptionSpecs{{"memory-budget", true},
                                                        {"temp-dir", true}};
struct MemoryOptions {
    std::uint64_t budgetBytes = 0; // 0: the default (half of physical memory)
    std::string tempDir;           // where sorted runs go; never empty
};
// The budget ("512M", "4G"; at least kMinMemoryBudget) and the scratch parent: --temp-dir
// (an existing folder), else the folder of `outputPath` when there is one, else $TMPDIR or
// /tmp. Throws UsageError naming the option.
MemoryOptions memoryOptions(const ParsedArgs& parsed, const std::string& outputPath);

// The extension of `path`, lower case, with its dot (".ply"); "" when it has none.
std::string lowerExtension(const std::string& path);

// `specs` followed by `more`.
std::vector<OptionSpec> withOptions(std::vector<OptionSpec> specs,
                                    const std::vector<OptionSpec>& more);

} // namespace omicron::cli
