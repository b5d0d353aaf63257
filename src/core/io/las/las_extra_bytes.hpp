// The LAS 1.4 Extra Bytes descriptors (LASF_Spec record 4, 192 bytes each): what the bytes
// after a record's standard fields hold, by name and type. The LAS column carries the bytes;
// these say what they mean, for `info` and for a LAS export that writes them back.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace omicron::las {

inline constexpr std::size_t kExtraBytesDescriptorBytes = 192;

struct ExtraBytesField {
    std::string name;
    std::string description;
    std::uint8_t dataType = 0; // 0 undocumented, 1-10 scalars, 11-30 (deprecated) arrays
    std::uint32_t bytes = 0;   // in the record
};

// The fields `descriptors` (a whole number of 192-byte descriptors) declare, in order.
std::vector<ExtraBytesField> parseExtraBytesDescriptors(std::span<const std::uint8_t> descriptors);

// "uint16", "float64[3]", "4 bytes" (undocumented): a field's type as info prints it.
std::string extraBytesTypeName(const ExtraBytesField& field);

// True when `descriptors` describe exactly `extraBytes` bytes a record (else they do not
// belong to the records: a writer's mistake, and the bytes are carried as undocumented).
bool describesExtraBytes(std::span<const std::uint8_t> descriptors, std::uint32_t extraBytes);

} // namespace omicron::las
