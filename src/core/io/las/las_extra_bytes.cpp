#include "io/las/las_extra_bytes.hpp"

#include "io/las/las_header.hpp"

#include <array>

namespace omicron::las {

namespace {

// Sizes and names of the scalar types 1-10; types 11-20 and 21-30 are arrays of two and three.
constexpr std::array<std::uint32_t, 11> kScalarBytes{0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
constexpr std::array<const char*, 11> kScalarNames{"",      "uint8", "int8",   "uint16",
                                                   "int16", "uint32", "int32", "uint64",
                                                   "int64", "float32", "float64"};

} // namespace

std::vector<ExtraBytesField> parseExtraBytesDescriptors(std::span<const std::uint8_t> descriptors) {
    std::vector<ExtraBytesField> fields;
    for (std::size_t at = 0; at + kExtraBytesDescriptorBytes <= descriptors.size();
         at += kExtraBytesDescriptorBytes) {
        const std::uint8_t* d = descriptors.data() + at;
        ExtraBytesField field;
        field.dataType = d[2];
        field.name = fixedLengthText(d + 4, 32);
        field.description = fixedLengthText(d + 160, 32);
        if (field.dataType == 0) {
            field.bytes = d[3]; // options: the byte count of undocumented bytes
        } else if (field.dataType <= 30) {
            const std::uint32_t scalar = (field.dataType - 1) % 10 + 1;
            field.bytes = kScalarBytes[scalar] * ((field.dataType - 1) / 10 + 1);
        }
        fields.push_back(std::move(field));
    }
    return fields;
}

std::string extraBytesTypeName(const ExtraBytesField& field) {
    if (field.dataType == 0 || field.dataType > 30) {
        return std::to_string(field.bytes) + " bytes";
    }
    const std::uint32_t scalar = (field.dataType - 1) % 10 + 1;
    const std::uint32_t count = (field.dataType - 1) / 10 + 1;
    std::string name = kScalarNames[scalar];
    return count == 1 ? name : name + "[" + std::to_string(count) + "]";
}

bool describesExtraBytes(std::span<const std::uint8_t> descriptors, std::uint32_t extraBytes) {
    if (descriptors.empty() || descriptors.size() % kExtraBytesDescriptorBytes != 0) {
        return false;
    }
    std::uint64_t total = 0;
    for (const ExtraBytesField& field : parseExtraBytesDescriptors(descriptors)) {
        if (field.dataType > 30) {
            return false;
        }
        total += field.bytes;
    }
    return total == extraBytes;
}

} // namespace omicron::las
