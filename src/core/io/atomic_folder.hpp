// Writes a folder of files so that the target is either the complete new folder or as it was:
// the files go into a temporary folder beside the target (same parent, so the final rename is
// one atomic step on the same file system), and commit() renames it into place. Destroyed
// without commit() (an error, an exception, a cancelled export), the temporary folder and
// everything in it is removed. A reader never sees a half-written folder under the target's
// name: for a Potree export, no metadata.json that announces an octree.bin still being written.
// A process killed outright leaves its temporary folder (its files have no names until
// complete, see AtomicFileWriter); the next AtomicFolder for the same target removes it, once
// the folder's name shows that its maker, a process of this machine, no longer runs.
#pragma once

#include <functional>
#include <string>

namespace omicron {

class AtomicFolder {
public:
    // Whether an existing folder may be replaced: called with its path, returns "" to allow,
    // or the reason to refuse (for the error message).
    using ReplaceCheck = std::function<std::string(const std::string& existingFolder)>;

    // Creates the temporary folder beside `targetPath`. An existing target must be a folder
    // that `mayReplace` accepts (checked now, so a refusal costs no work, and again at
    // commit). Throws OutputError naming the target.
    AtomicFolder(std::string targetPath, ReplaceCheck mayReplace);
    ~AtomicFolder();
    AtomicFolder(const AtomicFolder&) = delete;
    AtomicFolder& operator=(const AtomicFolder&) = delete;

    const std::string& targetPath() const { return m_targetPath; }
    // The temporary folder files are written to before commit().
    const std::string& tempPath() const { return m_tempPath; }
    // `name` inside the temporary folder.
    std::string file(const std::string& name) const;

    // Renames the temporary folder onto the target: a missing or empty target is replaced in
    // one rename, an existing one (accepted by the check) is exchanged with it atomically
    // (renameat2 RENAME_EXCHANGE) and then removed. Throws OutputError naming the target.
    void commit();

private:
    void checkTarget() const;

    std::string m_targetPath;
    std::string m_tempPath;
    ReplaceCheck m_mayReplace;
    bool m_committed = false;
};

} // namespace omicron
