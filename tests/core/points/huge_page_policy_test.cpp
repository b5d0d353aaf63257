#include "points/huge_page_policy.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <limits>
#include <string>
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

// A measurement that must not be taken.
FirstTouchCost unexpectedMeasure() {
    ADD_FAILURE() << "measured although the decision needs no measurement";
    return {};
}

// A measurement with the given costs, counting its calls.
std::function<FirstTouchCost()> measured(double huge, double small, int& calls) {
    return [=, &calls] {
        ++calls;
        return FirstTouchCost{huge, small};
    };
}

TEST_F(PageReportingFolder, HugePagesPayOffWithoutReporting) {
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder() + "/absent", unexpectedMeasure));
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder(), unexpectedMeasure)); // no counter
    reported("0");                                                           // no device reports
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder(), unexpectedMeasure));
}

TEST_F(PageReportingFolder, WhereFreeMemoryGoesBackToTheHostTheCheaperFirstTouchDecides) {
    reported("508863852");
    int calls = 0;
    // Huge pages rebuilt by the host: small ones win.
    EXPECT_FALSE(hugePagesPayOff(std::nullopt, folder(), measured(0.004, 0.0005, calls)));
    // Small pages dear (a hypervisor that shadows page tables): huge ones win.
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder(), measured(0.0001, 0.0035, calls)));
    // Equal: small pages, which the page recycler can reuse.
    EXPECT_FALSE(hugePagesPayOff(std::nullopt, folder(), measured(0.001, 0.001, calls)));
    // Transparent huge pages off.
    EXPECT_FALSE(hugePagesPayOff(std::nullopt, folder(),
                                 measured(std::numeric_limits<double>::infinity(), 1.0, calls)));
    EXPECT_EQ(calls, 4);
}

TEST_F(PageReportingFolder, TheEnvironmentOverridesEitherWay) {
    reported("4096");
    EXPECT_TRUE(hugePagesPayOff(std::string("1"), folder(), unexpectedMeasure));
    reported("0");
    EXPECT_FALSE(hugePagesPayOff(std::string("0"), folder(), unexpectedMeasure));
    // Anything else is no override.
    EXPECT_TRUE(hugePagesPayOff(std::string("yes"), folder(), unexpectedMeasure));
}

TEST_F(PageReportingFolder, AnUnreadableCounterMeansNoReporting) {
    reported("not a number");
    EXPECT_TRUE(hugePagesPayOff(std::nullopt, folder(), unexpectedMeasure));
}

// The real measurement: both costs are positive and finite (or huge pages infinite where the
// kernel has transparent huge pages off), and its mappings are gone afterwards.
TEST(FirstTouchCost, MeasuresBothPageSizesAndUnmapsWhatItTouched) {
    const auto mappings = [] {
        std::ifstream maps("/proc/self/maps");
        std::size_t lines = 0;
        for (std::string line; std::getline(maps, line);) {
            ++lines;
        }
        return lines;
    };
    const std::size_t before = mappings();
    const FirstTouchCost cost = measureFirstTouchCost();
    EXPECT_EQ(mappings(), before);
    EXPECT_GT(cost.smallSecondsPerMiB, 0.0);
    EXPECT_TRUE(std::isfinite(cost.smallSecondsPerMiB));
    EXPECT_GT(cost.hugeSecondsPerMiB, 0.0);
    std::ifstream modes("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string mode;
    if (std::getline(modes, mode) && mode.find("[never]") == std::string::npos) {
        EXPECT_TRUE(std::isfinite(cost.hugeSecondsPerMiB));
    }
}

} // namespace
} // namespace omicron
