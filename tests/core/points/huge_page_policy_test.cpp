#include "points/huge_page_policy.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace omicron {
namespace {

// A stand-in for /sys/module/page_reporting/parameters.
class PageReportingFolder : public ::testing::Test {
protected:
    void SetUp() override {
        m_folder = std::filesystem::temp_directory_path() /
                   ("omicron-page-reporting-" + std::to_string(::getpid()));
        std::filesystem::create_directories(m_folder);
    }
    void TearDown() override { std::filesystem::remove_all(m_folder); }

    void reported(const std::string& kib) {
        std::ofstream(m_folder / "reported_kib") << kib << "\n";
    }
    std::string folder() const { return m_folder.string(); }

private:
    std::filesystem::path m_folder;
};

TEST_F(PageReportingFolder, HugePagesPayOffWithoutReporting) {
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder() + "/absent"));
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder())); // the module without its counter
    reported("0");                                        // no device reports
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder()));
}

TEST_F(PageReportingFolder, SmallPagesWhereFreeMemoryGoesBackToTheHost) {
    reported("508863852");
    EXPECT_FALSE(hugePagesPayOff(std::nullopt, folder()));
}

TEST_F(PageReportingFolder, TheEnvironmentOverridesEitherWay) {
    reported("4096");
    EXPECT_TRUE(hugePagesPayOff(std::string("1"), folder()));
    reported("0");
    EXPECT_FALSE(hugePagesPayOff(std::string("0"), folder()));
    // Anything else is no override.
    EXPECT_TRUE(hugePagesPayOff(std::string("yes"), folder()));
}

TEST_F(PageReportingFolder, AnUnreadableCounterMeansNoReporting) {
    reported("not a number");
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder()));
}

} // namespace
} // namespace omicron
