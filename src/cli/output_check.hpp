// A command that reads its whole input before it writes (a sort, a conversion) checks its
// output first: a target that cannot be written fails at once, not after the work.
#pragma once

#include <string>

namespace omicron::cli {

// Makes (and removes) the temporary file an AtomicFileWriter would write `path` through:
// throws the OutputError the write would give (a missing folder, a folder for a name, no
// permission). Nothing is left behind either way.
void checkOutputWritable(const std::string& path);

} // namespace omicron::cli
