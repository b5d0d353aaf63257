// The records of a LAZ file as the decoder delivers them, and of a LAS file as stored: what the
// LAZ tests compare byte for byte.
#pragma once

#include "io/las/las_header.hpp"
#include "io/laz/laz_records.hpp"

#include <cstdint>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace omicron::test {

struct Records {
    las::Header header;
    std::vector<std::uint8_t> bytes; // every record, in file order
    std::uint64_t blocks = 0;
};

// Every record of a LAZ file, decoded in blocks (checked to come in order).
Records decodeLaz(const std::string& path, const LazStreaming& streaming = {});
// Every record of an uncompressed LAS file.
Records readLasRecords(const std::string& path);
// The first record that differs, as a readable failure.
::testing::AssertionResult sameRecords(const Records& decoded, const Records& reference);

} // namespace omicron::test
