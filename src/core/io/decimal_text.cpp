#include "io/decimal_text.hpp"

#include <charconv>
#include <cstdint>
#include <system_error>

namespace omicron {

namespace {

// Every power of ten up to 10^22 is an exact double (5^22 < 2^53).
constexpr double kPowersOfTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                   1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                   1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr int kMaxExactPower = 22;
constexpr std::uint64_t kMaxExactMantissa = std::uint64_t{1} << 53;
constexpr int kMaxMantissaDigits = 19; // 10^19 - 1 < 2^64

bool isDigit(char c) {
    return static_cast<unsigned>(c - '0') < 10u;
}

// [-]digits[.digits][(e|E)[+|-]digits] whose value one exact operation gives; false for any
// other text or value (the caller then asks from_chars, which decides).
bool parseExact(const char* p, const char* last, double& value) {
    const bool negative = p != last && *p == '-';
    if (negative) {
        ++p;
    }
    std::uint64_t mantissa = 0;
    int digits = 0; // significant digits in the mantissa: leading zeros do not count
    int exponent = 0;
    const auto takeDigit = [&](char c) {
        if (digits == kMaxMantissaDigits) {
            return false;
        }
        mantissa = mantissa * 10 + static_cast<std::uint64_t>(c - '0');
        digits += mantissa != 0 ? 1 : 0;
        return true;
    };
    const char* integer = p;
    for (; p != last && isDigit(*p); ++p) {
        if (!takeDigit(*p)) {
            return false;
        }
    }
    if (p == integer) {
        return false; // ".5", "nan", "-inf", ...
    }
    if (p != last && *p == '.') {
        const char* fraction = ++p;
        for (; p != last && isDigit(*p); ++p) {
            if (!takeDigit(*p)) {
                return false;
            }
            --exponent;
        }
        if (p == fraction) {
            return false; // "5."
        }
    }
    if (p != last && (*p == 'e' || *p == 'E')) {
        ++p;
        const bool negativeExponent = p != last && *p == '-';
        if (p != last && (*p == '+' || *p == '-')) {
            ++p;
        }
        const char* exponentDigits = p;
        int written = 0;
        for (; p != last && isDigit(*p); ++p) {
            if (p - exponentDigits == 4) {
                return false; // far beyond 10^22 either way, or leading zeros: from_chars
            }
            written = written * 10 + (*p - '0');
        }
        if (p == exponentDigits) {
            return false;
        }
        exponent += negativeExponent ? -written : written;
    }
    if (p != last || mantissa > kMaxExactMantissa || exponent > kMaxExactPower ||
        exponent < -kMaxExactPower) {
        return false;
    }
    double result = static_cast<double>(mantissa); // exact
    if (exponent < 0) {
        result /= kPowersOfTen[-exponent]; // both exact: one correctly rounded division
    } else {
        result *= kPowersOfTen[exponent];
    }
    value = negative ? -result : result;
    return true;
}

} // namespace

bool parseDecimal(std::string_view text, double& value) {
    const char* first = text.data();
    const char* last = first + text.size();
    if (first != last && *first == '+') { // from_chars rejects a leading '+', strtod takes it
        ++first;
        if (first != last && *first == '-') {
            return false;
        }
    }
    if (first == last) {
        return false;
    }
    if (parseExact(first, last, value)) {
        return true;
    }
    const auto [end, error] = std::from_chars(first, last, value);
    return error == std::errc() && end == last;
}

} // namespace omicron
