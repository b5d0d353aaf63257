// The body of the PLY, LAS, LAZ and XYZ targets: open the bytes as a file of that kind and read
// every point; InputError is the expected answer to bad bytes.
#pragma once

#include "fuzz_input.hpp"
#include "io/input_error.hpp"
#include "io/point_reader.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace omicron::fuzz {

template <typename Open>
int readCloud(const std::uint8_t* data, std::size_t size, const std::string& name, Open open) {
    const std::string path = writeInput(data, size, name);
    try {
        std::unique_ptr<PointReader> reader = open(path, OpenOptions{});
        std::uint64_t points = 0;
        reader->read([&](const PointBatch& batch) { points += batch.size(); });
        if (points > reader->info().pointCount) {
            __builtin_trap(); // more points than the file holds: a reader bug
        }
    } catch (const InputError&) {
    }
    return 0;
}

} // namespace omicron::fuzz
