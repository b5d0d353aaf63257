#include "cli_args.hpp"

#include "memory_budget.hpp"
#include "sort/morton_sorter.hpp"
#include "sort/scratch_folder.hpp"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <tbb/info.h>

namespace omicron::cli {

bool ParsedArgs::flag(std::string_view name) const {
    return value(name).has_value();
}

std::optional<std::string> ParsedArgs::value(std::string_view name) const {
    for (auto it = m_options.rbegin(); it != m_options.rend(); ++it) {
        if (it->first == name) {
            return it->second;
        }
    }
    return std::nullopt;
}

void ParsedArgs::set(const std::string& name, std::string value) {
    m_options.emplace_back(name, std::move(value));
}

ParsedArgs parseArgs(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs) {
    ParsedArgs parsed;
    bool optionsEnded = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& arg = args[i];
        if (optionsEnded || arg == "-" || arg.empty() || arg[0] != '-') {
            parsed.positionals.push_back(arg);
            continue;
        }
        if (arg == "--") {
            optionsEnded = true;
            continue;
        }
        if (arg == "--help" || arg == "-h") {
            parsed.help = true;
            continue;
        }
        const std::size_t equals = arg.find('=');
        const std::string name =
            arg.substr(2, equals == std::string::npos ? std::string::npos : equals - 2);
        const auto spec = std::find_if(specs.begin(), specs.end(),
                                       [&](const OptionSpec& s) { return s.name == name; });
        if (arg.rfind("--", 0) != 0 || spec == specs.end()) {
            throw UsageError("unknown option '" + arg.substr(0, equals) + "'");
        }
        if (!spec->takesValue) {
            if (equals != std::string::npos) {
                throw UsageError("option --" + name + " takes no value");
            }
            parsed.set(name, "");
        } else if (equals != std::string::npos) {
            parsed.set(name, arg.substr(equals + 1));
        } else if (i + 1 < args.size()) {
            parsed.set(name, args[++i]);
        } else {
            throw UsageError("option --" + name + " needs a value");
        }
    }
    return parsed;
}

std::uint64_t parseInteger(const std::string& text, const std::string& option, std::uint64_t min,
                           std::uint64_t max) {
    std::uint64_t value = 0;
    const char* first = text.data();
    const char* last = first + text.size();
    const auto [end, error] = std::from_chars(first, last, value);
    const bool digitsOnly = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
        return c >= '0' && c <= '9';
    });
    if (!digitsOnly || end != last || error == std::errc::invalid_argument) {
        throw UsageError("bad number for --" + option + ": '" + text +
                         "' (expected a whole number " + std::to_string(min) + ".." +
                         std::to_string(max) + ")");
    }
    if (error == std::errc::result_out_of_range || value < min || value > max) {
        throw UsageError("--" + option + " " + text + " is out of range (expected " +
                         std::to_string(min) + ".." + std::to_string(max) + ")");
    }
    return value;
}

int threadsOption(const ParsedArgs& parsed) {
    const auto text = parsed.value("threads");
    return text ? static_cast<int>(parseInteger(*text, "threads", 1, 1024))
                : tbb::info::default_concurrency();
}

int sortChunksOption(const ParsedArgs& parsed) {
    const auto text = parsed.value("chunks");
    return text ? static_cast<int>(parseInteger(*text, "chunks", 1, kMaxSortChunks))
                : kDefaultSortChunks;
}

MemoryOptions memoryOptions(const ParsedArgs& parsed, const std::string& outputPath) {
    MemoryOptions memory;
    if (const auto text = parsed.value("memory-budget")) {
        const std::optional<std::uint64_t> bytes = parseByteSize(*text);
        if (!bytes) {
            throw UsageError("bad size for --memory-budget: '" + *text +
                             "' (expected e.g. 512M, 4G or a number of bytes)");
        }
        if (*bytes < kMinMemoryBudget) {
            throw UsageError("--memory-budget " + *text + " is below the minimum of " +
                             formatByteSize(kMinMemoryBudget));
        }
        memory.budgetBytes = *bytes;
    }
    if (const auto folder = parsed.value("temp-dir")) {
        std::error_code error;
        if (!std::filesystem::is_directory(*folder, error)) {
            throw UsageError("--temp-dir '" + *folder + "' is not an existing folder");
        }
        memory.tempDir = *folder;
    } else if (!outputPath.empty()) {
        // Beside the output: the disk meant for big files, rather than a /tmp that may be
        // small or in memory.
        const std::filesystem::path parent = std::filesystem::path(outputPath).parent_path();
        memory.tempDir = parent.empty() ? "." : parent.string();
    } else {
        memory.tempDir = ScratchFolder::defaultParent();
    }
    return memory;
}

std::string lowerExtension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    for (char& c : extension) {
        c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    }
    return extension;
}

std::vector<OptionSpec> withOptions(std::vector<OptionSpec> specs,
                                    const std::vector<OptionSpec>& more) {
    specs.insert(specs.end(), more.begin(), more.end());
    return specs;
}

} // namespace omicron::cli
