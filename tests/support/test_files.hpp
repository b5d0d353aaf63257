// Helpers shared by the tests: temporary folders, the shared real-data folder, raw bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace omicron::test {

// A fresh folder under the system temp dir, removed with everything in it on destruction.
class TempDir {
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return m_path; }
    std::string file(const std::string& name) const { return (m_path / name).string(); }

private:
    std::filesystem::path m_path;
};

// ../shared/data/NAME, or "" when the file is absent (call GTEST_SKIP then).
std::string sharedDataFile(const std::string& name);

// tests/data/NAME: small files kept in the repository (always present).
std::string repoDataFile(const std::string& name);

// Expands to GTEST_SKIP() with a message when ../shared/data/NAME is absent; else sets VAR.
#define OMICRON_REQUIRE_SHARED_FILE(VAR, NAME)                                                     \
    const std::string VAR = ::omicron::test::sharedDataFile(NAME);                                 \
    if (VAR.empty()) {                                                                             \
        GTEST_SKIP() << "shared data file " << (NAME) << " is absent (../shared/data); skipped";   \
    }

// A parameterised test's name for a data file name: "bunny.ply" -> "bunny_ply",
// "laz/a-b.laz" -> "laz_a_b_laz".
std::string fileParamName(std::string fileName);
// The same as INSTANTIATE_TEST_SUITE_P's name generator, for tests parameterised by file name.
struct FileParamName {
    template <typename ParamInfo> std::string operator()(const ParamInfo& info) const {
        return fileParamName(info.param);
    }
};

void writeBytes(const std::string& path, const std::vector<std::uint8_t>& bytes);
void writeText(const std::string& path, const std::string& text);
std::vector<std::uint8_t> readBytes(const std::string& path);

} // namespace omicron::test
