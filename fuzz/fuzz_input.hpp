// What every fuzz target shares: the bytes under test as a file (the readers take paths), and
// the rule that a reader given any bytes either reads them or throws InputError — nothing else
// may escape (no other exception, no crash, no unbounded allocation, no hang).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace omicron::fuzz {

// Writes `data` to a file named `name` in a folder of this process (in /dev/shm where there is
// one) and returns its path; the same path every call, overwritten.
std::string writeInput(const std::uint8_t* data, std::size_t size, const std::string& name);

} // namespace omicron::fuzz

// Every target defines this (libFuzzer's entry point; the standalone driver calls it too).
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
