// Fuzz target: the .oms reader (sorted stream) on any bytes: open, stream every range.
#include "formats/oms_reader.hpp"
#include "fuzz_input.hpp"
#include "io/input_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = omicron::fuzz::writeInput(data, size, "input.oms");
    try {
        omicron::OmsReader reader(path);
        reader.read([](const omicron::SortedCloud&, std::size_t, std::size_t) {});
    } catch (const omicron::InputError&) {
    }
    return 0;
}
