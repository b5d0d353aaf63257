// Numbers in error messages as hexadecimal: checksums and Morton codes (16 digits, so two
// codes line up), small header fields with fewer. Shared by every stage.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace omicron {

// "0x" and `digits` lower-case hex digits (more when the value needs them).
inline std::string hexText(std::uint64_t value, int digits = 16) {
    char text[19];
    std::snprintf(text, sizeof(text), "0x%0*llx", digits, static_cast<unsigned long long>(value));
    return text;
}

} // namespace omicron
