// Fuzz target: the .omh reader (saved hierarchy) on any bytes: open, load every level, verify.
#include "formats/omh_reader.hpp"
#include "fuzz_input.hpp"
#include "io/input_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = omicron::fuzz::writeInput(data, size, "input.omh");
    try {
        omicron::OmhReader reader(path);
        reader.load();
        reader.verify();
    } catch (const omicron::InputError&) {
    }
    return 0;
}
