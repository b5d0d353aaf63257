// omicron-cli info for .omh hierarchy files: what the header and level table say, and with
// --verify every section's checksum.
#pragma once

#include <string>

namespace omicron::cli {

// Prints the description of the .omh file at `path` (text, or one JSON object whose "levels"
// array has the shape of build --json's). Returns the exit status; throws InputError.
int printOmhInfo(const std::string& path, bool json, bool verify);

} // namespace omicron::cli
