// Runs a program as a real child process and captures what it prints, for CLI tests.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
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

// A child left running, for tests that kill it part way (e.g. in the middle of a save).
// Its stdout goes to /dev/null and its stderr to `errPath`; `environment` entries
// ("NAME=VALUE") are added to this process's environment. The destructor kills (SIGKILL) and
// reaps a child still running, so a failing test never leaves one behind.
class RunningProcess {
public:
    RunningProcess(const std::string& program, const std::vector<std::string>& args,
                   const std::vector<std::string>& environment, const std::string& errPath);
    ~RunningProcess();
    RunningProcess(const RunningProcess&) = delete;
    RunningProcess& operator=(const RunningProcess&) = delete;

    // Sends SIGKILL and waits for the child to end.
    void kill();
    // Sends `signalNumber` (SIGINT is what Ctrl+C sends).
    void signal(int signalNumber);
    // Waits up to `timeout` for the child to end: its exit code (-1 when a signal ended it),
    // or nothing while it still runs.
    std::optional<int> waitFor(std::chrono::milliseconds timeout);
    // The child's process ID, -1 once it has ended and been reaped.
    int pid() const { return m_pid; }

private:
    int m_pid = -1;
};

// The files process `pid` (0: this process) has open in `folder`, named or not, as their
// descriptors' /proc links ("/proc/PID/fd/N": stat() and open() through one reach the file;
// a nameless file's link still names its folder: "/FOLDER/#INODE (deleted)").
std::vector<std::filesystem::path> openFilesIn(int pid, const std::filesystem::path& folder);

} // namespace omicron::test
