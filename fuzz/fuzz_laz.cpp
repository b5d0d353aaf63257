// Fuzz target: the LAZ reader (openLasReader) on any bytes.
#include "fuzz_cloud_reader.hpp"
#include "fuzz_input.hpp"
#include "io/las/las_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return omicron::fuzz::readCloud(data, size, "input.laz", omicron::openLasReader);
}
