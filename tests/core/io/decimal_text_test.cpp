// parseDecimal against std::from_chars, the rule it stands in for: the same double bit for bit
// for every number, and the same yes or no for every other text, on hand-picked edge cases and
// on a million random decimals of the forms scanners and converters write.
#include "io/decimal_text.hpp"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <gtest/gtest.h>
#include <random>
#include <string>
#include <system_error>

namespace omicron {
namespace {

// from_chars with strtod's leading '+' (but not "+-"), the whole text or nothing.
bool reference(std::string_view text, double& value) {
    if (!text.empty() && text.front() == '+') {
        text.remove_prefix(1);
        if (!text.empty() && text.front() == '-') {
            return false;
        }
    }
    if (text.empty()) {
        return false;
    }
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && end == text.data() + text.size();
}

void expectSameAsFromChars(const std::string& text) {
    double expected = 0.0;
    double parsed = 0.0;
    const bool expectedOk = reference(text, expected);
    ASSERT_EQ(parseDecimal(text, parsed), expectedOk) << "'" << text << "'";
    if (expectedOk) {
        if (std::isnan(expected)) {
            EXPECT_TRUE(std::isnan(parsed)) << text;
        } else {
            EXPECT_EQ(std::bit_cast<std::uint64_t>(parsed), std::bit_cast<std::uint64_t>(expected))
                << "'" << text << "': " << parsed << " against " << expected;
        }
    }
}

TEST(DecimalText, EdgeCasesAgreeWithFromChars) {
    for (const char* text : {"0",
                             "-0",
                             "+0",
                             "0.0",
                             "-0.0",
                             "1",
                             "-1",
                             "+1",
                             "+-1",
                             "-+1",
                             "",
                             "+",
                             "-",
                             ".",
                             "5.",
                             ".5",
                             "-.5",
                             "1e5",
                             "1E5",
                             "1e+5",
                             "1e-5",
                             "1e",
                             "1e+",
                             "1e-",
                             "e5",
                             "1.5e22",
                             "1.5e23",
                             "1e-22",
                             "1e-23",
                             "9007199254740992",
                             "9007199254740993",
                             "9007199254740992.5",
                             "1234567890123456789",
                             "12345678901234567890",
                             "0.1",
                             "0.2",
                             "0.3",
                             "123.456",
                             "637172.26998",
                             "849399.56997",
                             "411.22000",
                             "000000000000000000000001.5",
                             "1.00000000000000000000",
                             "0.000000000000000000000000001",
                             "1e0000",
                             "1e00005",
                             "1e308",
                             "1e309",
                             "-1e309",
                             "1e-324",
                             "4.9e-324",
                             "2.2250738585072014e-308",
                             "nan",
                             "-nan",
                             "NaN",
                             "inf",
                             "-inf",
                             "infinity",
                             "0x1p3",
                             "1.2.3",
                             "1,5",
                             "1 ",
                             " 1",
                             "1-",
                             "--1",
                             "1e5.5",
                             "7.",
                             "12345678901234567.0",
                             "1.7976931348623157e308"}) {
        expectSameAsFromChars(text);
    }
}

TEST(DecimalText, RandomDecimalsAgreeWithFromChars) {
    std::mt19937_64 random(20261128);
    std::uniform_real_distribution<double> coordinate(-1e6, 1e6);
    std::uniform_int_distribution<int> decimals(0, 12);
    std::uniform_int_distribution<int> exponent(-30, 30);
    std::uniform_int_distribution<std::uint64_t> anyMantissa(0, ~std::uint64_t{0} >> 10);
    char text[64];
    for (int i = 0; i < 1'000'000; ++i) {
        switch (i % 4) {
        case 0: // fixed notation, as XYZ exports write coordinates
            std::snprintf(text, sizeof text, "%.*f", decimals(random), coordinate(random));
            break;
        case 1: // scientific notation with up to 17 significant digits
            std::snprintf(text, sizeof text, "%.*e", decimals(random) + 4, coordinate(random));
            break;
        case 2: // an integer mantissa and a power of ten beyond the exact ones now and then
            std::snprintf(text, sizeof text, "%llue%d",
                          static_cast<unsigned long long>(anyMantissa(random)), exponent(random));
            break;
        default: // shortest round trip
            std::snprintf(text, sizeof text, "%.17g", coordinate(random) * 1e-3);
            break;
        }
        expectSameAsFromChars(text);
        if (testing::Test::HasFailure()) {
            return;
        }
    }
}

} // namespace
} // namespace omicron
