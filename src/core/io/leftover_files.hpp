// Files and folders a process names after itself (PREFIX, its PID, then a tail) so that,
// killed outright (SIGKILL, a crash, the out-of-memory killer) and unable to remove them, it
// leaves them to the next process that makes the same kind: that one removes those whose PID
// no longer runs. Save temporaries (AtomicFileWriter), the Potree export's temporary folder
// and the benchmarks' scratch use it.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace omicron {

// This boot of this machine and this PID namespace ("BOOTID8.PIDNS"), to put in such names
// before the PID: a PID means a process here only where the name carries the same token (a
// folder shared over the network or with a container holds other machines' PIDs). "" where
// /proc cannot tell; then nothing may be removed by PID.
std::string processToken();

// ".NAME.tmp-TOKEN-" (".NAME.tmp-" for an empty token): how the name of a temporary standing in
// for the file or folder NAME begins, before its maker's PID. Save temporaries and the Potree
// export's temporary folder are named so.
std::string temporaryPrefix(const std::string& name, const std::string& token);

// Removes, with what they hold, the entries of `folder` named `prefix` + a PID + a tail that
// `tailMatches` accepts, whose process is gone (kill(PID, 0) gives ESRCH). Best effort: what
// cannot be listed or removed stays, and nothing is thrown.
void removeLeftoversOfGoneProcesses(const std::filesystem::path& folder, const std::string& prefix,
                                    const std::function<bool(std::string_view tail)>& tailMatches);

} // namespace omicron
