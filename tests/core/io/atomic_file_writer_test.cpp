// AtomicFileWriter::extendTo: the region a save fills out of order (the .omh's deep levels)
// is reserved on a disk and only checked on a tmpfs, where reserving means zeroing memory.
#include "io/atomic_file_writer.hpp"
#include "run_process.hpp"
#include "test_files.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <linux/magic.h>
#include <string>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/vfs.h>
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

} // namespace
} // namespace omicron
