#include "nameless_file.hpp"

#include <cerrno>
#include <fcntl.h>
#include <unistd.h>
#include <vector>

namespace omicron {

namespace {

std::string procPath(int fd) {
    return "/proc/self/fd/" + std::to_string(fd);
}

bool lacksTmpfile(int error) {
    // What open(2) gives where the file system (or an old kernel) has no O_TMPFILE.
    return error == EOPNOTSUPP || error == EISDIR || error == EINVAL;
}

} // namespace

int openNamelessFile(const std::string& folder, mode_t mode) {
    return ::open(folder.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, mode);
}

int openScratchFile(const std::string& folder, const std::string& stem) {
    const int fd = openNamelessFile(folder, 0600);
    if (fd >= 0 || !lacksTmpfile(errno)) {
        return fd;
    }
    std::string pattern = folder + "/" + stem + "XXXXXX";
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    const int named = ::mkostemp(name.data(), O_CLOEXEC);
    if (named >= 0) {
        ::unlink(name.data());
    }
    return named;
}

bool nameFile(int fd, const std::string& path) {
    return ::linkat(AT_FDCWD, procPath(fd).c_str(), AT_FDCWD, path.c_str(), AT_SYMLINK_FOLLOW) == 0;
}

bool canNameFiles(int fd) {
    return ::access(procPath(fd).c_str(), F_OK) == 0;
}

} // namespace omicron
