// AtomicFileWriter::extendTo: the region a save fills out of order (the .omh's deep levels)
// is reserved on a disk and only checked on a tmpfs, where reserving means zeroing memory; a
// big file is persisted while it is written; and the temporaries a killed writer left are
// removed by the next writer of the same target.
#include "io/atomic_file_writer.hpp"
#include "io/leftover_files.hpp"
#include "run_process.hpp"
#include "test_files.hpp"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <linux/magic.h>
#include <string>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/vfs.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace omicron {
namespace {

// A scratch folder on /dev/shm, or none where that is not a tmpfs.
class ShmDir {
public:
    ShmDir() {
        struct statfs fs {};
        if (::statfs("/dev/shm", &fs) != 0 || fs.f_type != TMPFS_MAGIC) {
            return;
        }
        std::string pattern = "/dev/shm/omicron-writer-test-XXXXXX";
        if (::mkdtemp(pattern.data()) != nullptr) {
            m_path = pattern;
        }
    }
    ~ShmDir() {
        if (!m_path.empty()) {
            std::filesystem::remove_all(m_path);
        }
    }
    ShmDir(const ShmDir&) = delete;
    ShmDir& operator=(const ShmDir&) = delete;
    const std::filesystem::path& path() const { return m_path; }

private:
    std::filesystem::path m_path;
};

std::size_t entriesIn(const std::filesystem::path& dir) {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir),
                                                  std::filesystem::directory_iterator()));
}

std::vector<char> contentsOf(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Writes a header to `folder`/out.bin, extends the file, fills the extended region back to
// front with writeAt and appends a footer: the file must hold exactly that, whatever extendTo
// did underneath, and be the folder's only entry.
void expectOutOfOrderFillIsTheFile(const std::filesystem::path& folder) {
    const std::string path = (folder / "out.bin").string();
    constexpr std::size_t kRegion = 3 << 20;
    AtomicFileWriter file(path);
    const std::string header = "header";
    file.write(header);
    file.extendTo(header.size() + kRegion);
    std::vector<char> expected(header.begin(), header.end());
    expected.resize(header.size() + kRegion);
    constexpr std::size_t kPiece = 1 << 20;
    for (std::size_t piece = kRegion / kPiece; piece-- > 0;) {
        std::vector<char> bytes(kPiece, static_cast<char>('a' + piece));
        file.writeAt(header.size() + piece * kPiece, bytes.data(), bytes.size());
        std::copy(bytes.begin(), bytes.end(), expected.begin() + header.size() + piece * kPiece);
    }
    const std::string footer = "footer";
    file.write(footer);
    expected.insert(expected.end(), footer.begin(), footer.end());
    file.commit();
    EXPECT_EQ(contentsOf(path), expected);
    EXPECT_EQ(entriesIn(folder), 1u) << "the temporary file was left behind";
}

TEST(AtomicFileWriterExtend, TheExtendedRegionFilledOutOfOrderIsTheFileOnADisk) {
    test::TempDir dir;
    expectOutOfOrderFillIsTheFile(dir.path());
}

TEST(AtomicFileWriterExtend, TheExtendedRegionFilledOutOfOrderIsTheFileOnATmpfs) {
    ShmDir dir;
    if (dir.path().empty()) {
        GTEST_SKIP() << "/dev/shm is not a tmpfs here";
    }
    expectOutOfOrderFillIsTheFile(dir.path());
}

// On a tmpfs the region is not reserved (its pages would be zeroed on the spot): the file
// stays sparse until written, and no room is still an error before anything is written.
TEST(AtomicFileWriterExtend, OnATmpfsTheRegionStaysSparseUntilWritten) {
    ShmDir dir;
    if (dir.path().empty()) {
        GTEST_SKIP() << "/dev/shm is not a tmpfs here";
    }
    AtomicFileWriter file((dir.path() / "out.bin").string());
    constexpr std::uint64_t kSize = std::uint64_t{256} << 20;
    file.extendTo(kSize);
    EXPECT_EQ(entriesIn(dir.path()), 0u) << "the temporary has a name before it is complete";
    const std::vector<std::filesystem::path> open = test::openFilesIn(0, dir.path());
    ASSERT_EQ(open.size(), 1u);
    const std::filesystem::path temporary = open.front();
    struct stat status {};
    ASSERT_EQ(::stat(temporary.c_str(), &status), 0);
    EXPECT_EQ(static_cast<std::uint64_t>(status.st_size), kSize);
    EXPECT_LT(static_cast<std::uint64_t>(status.st_blocks) * 512, kSize / 16)
        << "the region was allocated up front";
}

TEST(AtomicFileWriterExtend, OnATmpfsWithoutTheRoomItIsAClearErrorAndNothingIsLeft) {
    ShmDir dir;
    if (dir.path().empty()) {
        GTEST_SKIP() << "/dev/shm is not a tmpfs here";
    }
    struct statvfs fs {};
    ASSERT_EQ(::statvfs(dir.path().c_str(), &fs), 0);
    const std::uint64_t size = std::uint64_t{fs.f_bavail} * fs.f_frsize + (std::uint64_t{1} << 30);
    const std::string path = (dir.path() / "out.bin").string();
    try {
        AtomicFileWriter file(path);
        file.extendTo(size);
        FAIL() << "extending beyond the free space of the tmpfs succeeded";
    } catch (const OutputError& error) {
        const std::string message = error.what();
        EXPECT_EQ(message.rfind(
                      path + ": no room for the " + std::to_string(size) + " bytes of the file", 0),
                  0u)
            << message;
    }
    EXPECT_EQ(entriesIn(dir.path()), 0u) << "the temporary file was left behind";
}

// A file of `mebibytes` MiB, each MiB a different byte, written in 1 MiB appends.
std::vector<char> writeMebibytes(AtomicFileWriter& file, std::size_t mebibytes) {
    std::vector<char> expected;
    for (std::size_t m = 0; m < mebibytes; ++m) {
        const std::vector<char> piece(std::size_t{1} << 20, static_cast<char>('A' + m % 26));
        file.write(piece.data(), piece.size());
        expected.insert(expected.end(), piece.begin(), piece.end());
    }
    return expected;
}

// A big file is persisted while it is written (each 16 MiB window written back wakes the
// writer's flushing thread), and the committed file is exactly what was written.
TEST(AtomicFileWriterFlush, ABigFileIsPersistedWhileWrittenAndCommitsTheSameBytes) {
    test::TempDir dir;
    const std::string path = dir.file("big.bin");
    AtomicFileWriter file(path);
    const std::vector<char> expected = writeMebibytes(file, 40);
    // The thread runs on its own: wait for its first flush (a liveness bound, not a timing).
    for (int wait = 0; wait < 3000 && file.backgroundFlushes() == 0; ++wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_GT(file.backgroundFlushes(), 0u) << "40 MiB were written and nothing was persisted";
    file.commit();
    EXPECT_EQ(contentsOf(path), expected);
    EXPECT_EQ(entriesIn(dir.path()), 1u) << "the temporary file was left behind";
}

// A small file (no window written back) starts no thread: commit's fsync alone persists it.
TEST(AtomicFileWriterFlush, ASmallFileIsPersistedByTheCommitAlone) {
    test::TempDir dir;
    AtomicFileWriter file(dir.file("small.bin"));
    const std::vector<char> expected = writeMebibytes(file, 3);
    file.commit();
    EXPECT_EQ(file.backgroundFlushes(), 0u);
    EXPECT_EQ(contentsOf(dir.file("small.bin")), expected);
}

// A writer abandoned while its thread may be flushing (an error half-way through a save)
// stops the thread and leaves nothing behind; the target is not created.
TEST(AtomicFileWriterFlush, AnAbandonedWriterStopsFlushingAndLeavesNothing) {
    test::TempDir dir;
    {
        AtomicFileWriter file(dir.file("abandoned.bin"));
        writeMebibytes(file, 40);
    }
    EXPECT_EQ(entriesIn(dir.path()), 0u);
}

// A PID whose process has ended (a child that exited and was reaped), or 0 where that PID was
// taken again at once.
pid_t pidOfAGoneProcess() {
    const pid_t child = ::fork();
    if (child == 0) {
        ::_exit(0);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    return ::kill(child, 0) != 0 && errno == ESRCH ? child : 0;
}

void touch(const std::filesystem::path& path) {
    std::ofstream(path) << "left behind";
}

// A process killed between naming its finished temporary and renaming it (or one writing
// where files cannot be nameless) leaves ".NAME.tmp-TOKEN-PID-…": the next writer of the same
// target removes those of gone processes, and nothing of a running one or of another target.
TEST(AtomicFileWriterLeftovers, TheNextWriterOfATargetRemovesTemporariesOfGoneProcesses) {
    const std::string token = processToken();
    if (token.empty()) {
        GTEST_SKIP() << "/proc cannot tell this boot and PID namespace here";
    }
    const pid_t gone = pidOfAGoneProcess();
    ASSERT_NE(gone, 0) << "the child's PID was reused at once";
    test::TempDir dir;
    const std::string prefix = ".out.bin.tmp-" + token + "-";
    const std::string goneNamed = prefix + std::to_string(gone) + "-3";         // named at commit
    const std::string goneFallback = prefix + std::to_string(gone) + "-aZ09xQ"; // mkostemp's
    const std::string running = prefix + std::to_string(::getppid()) + "-0";
    const std::string otherTarget = ".other.bin.tmp-" + token + "-" + std::to_string(gone) + "-0";
    const std::string otherMachine = ".out.bin.tmp-0000beef.1-" + std::to_string(gone) + "-0";
    const std::string notOurs = prefix + std::to_string(gone) + "-0.keep";
    for (const std::string& name :
         {goneNamed, goneFallback, running, otherTarget, otherMachine, notOurs}) {
        touch(dir.path() / name);
    }

    AtomicFileWriter file(dir.file("out.bin"));
    file.write(std::string("new"));
    file.commit();

    EXPECT_EQ(contentsOf(dir.file("out.bin")), (std::vector<char>{'n', 'e', 'w'}));
    EXPECT_FALSE(std::filesystem::exists(dir.path() / goneNamed));
    EXPECT_FALSE(std::filesystem::exists(dir.path() / goneFallback));
    for (const std::string& kept : {running, otherTarget, otherMachine, notOurs}) {
        EXPECT_TRUE(std::filesystem::exists(dir.path() / kept)) << kept << " was removed";
    }
    EXPECT_EQ(entriesIn(dir.path()), 5u);
}

} // namespace
} // namespace omicron
