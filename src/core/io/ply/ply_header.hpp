// PLY header parsing (version 1.0): the elements, their properties and where the body starts.
//
// Kept apart from the body reader so that every header rule (and every header error) lives in
// one place; the reader only decides what to do with the parsed layout.
#pragma once

#include "io/file_stream.hpp"
#include "io/point_reader.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace omicron {

enum class PlyScalarType : std::uint8_t {
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Float32,
    Float64
};

std::size_t plyScalarBytes(PlyScalarType type);
const char* plyScalarName(PlyScalarType type); // the PLY spelling: "char", "uchar", ...

struct PlyProperty {
    std::string name;
    PlyScalarType type = PlyScalarType::Float32; // the item type of a list
    bool isList = false;
    PlyScalarType countType = PlyScalarType::UInt8; // lists only: always an integer type
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
    std::uint64_t headerLine = 0; // 1-based line of its "element" line, for error messages

    bool hasLists() const;
    // Bytes per binary record; only meaningful when !hasLists().
    std::uint64_t recordBytes() const;
    // The fewest bytes one record can take (lists counted as empty): binary and ascii bounds
    // for the "does the body fit in the file" checks.
    std::uint64_t minimumBinaryBytes() const;
    // -1 when the element has no property of that name.
    int findProperty(std::string_view propertyName) const;
};

struct PlyHeader {
    CloudFormat format = CloudFormat::PlyBinaryLittleEndian;
    std::vector<PlyElement> elements;
    bool hasOffset = false;
    glm::dvec3 offset{0.0};          // from "comment offset X Y Z": source = stored + offset
    std::uint64_t bodyOffset = 0;    // byte just after the "end_header" line
    std::uint64_t bodyFirstLine = 0; // 1-based line number of the first body line
    std::uint64_t endHeaderLine = 0;
};

// Reads and parses the header from the start of `stream`; leaves the stream position
// unspecified. Throws InputError (UnknownFormat, MalformedHeader, UnsupportedFeature,
// Truncated) naming the header line and what was expected there.
PlyHeader parsePlyHeader(FileStream& stream);

} // namespace omicron
