// Fuzz target: the XYZ reader (openXyzReader) on any bytes.
#include "fuzz_cloud_reader.hpp"
#include "fuzz_input.hpp"
#include "io/xyz/xyz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return omicron::fuzz::readCloud(data, size, "input.xyz", omicron::openXyzReader);
}
