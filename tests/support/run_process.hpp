// Runs a program as a real child process and captures what it prints, for CLI tests.
#pragma once

#include <string>
#include <vector>

namespace omicron::test {

struct ProcessResult {
    int exitCode = -1; // -1 when the child did not exit normally
    std::string out;
    std::string err;
};

// Runs `program` with `args` (no shell), waits for it and returns its exit code and output.
ProcessResult runProcess(const std::string& program, const std::vector<std::string>& args);

} // namespace omicron::test
