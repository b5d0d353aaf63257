// Files without a name, so that none outlives its process however that process ends: a
// SIGKILL, a crash or the kernel's out-of-memory killer take the descriptors with them, and
// the kernel frees a file with no name and no descriptor. Scratch files (sorted runs, a
// cloud beyond the memory budget) never need a name; a save's temporary gets one only at the
// instant it replaces its target.
#pragma once

#include <string>
#include <sys/types.h>

namespace omicron {

// A new empty file in `folder`, open for reading and writing (close-on-exec), with no name
// (O_TMPFILE), permissions `mode` before the umask. Returns -1 with errno set where the folder
// cannot take one: no such folder, no permission, or a file system without O_TMPFILE
// (EOPNOTSUPP, EISDIR or EINVAL there). Such a file can be given a name later (nameFile).
int openNamelessFile(const std::string& folder, mode_t mode);

// For scratch: as openNamelessFile, and on a file system without O_TMPFILE a named file
// ("FOLDER/STEM" plus six random characters, mode 0600) unlinked at once, nameless but for
// that instant. Returns -1 with errno set when neither can be made.
int openScratchFile(const std::string& folder, const std::string& stem);

// Gives a file from openNamelessFile the name `path`, in the folder it was opened in; `path`
// must not exist. Through /proc/self/fd (linkat with AT_EMPTY_PATH needs a capability).
// Returns false with errno set (EEXIST when `path` exists).
bool nameFile(int fd, const std::string& path);

// Whether nameFile can name `fd`: its /proc/self/fd link exists (/proc is mounted here).
bool canNameFiles(int fd);

} // namespace omicron
