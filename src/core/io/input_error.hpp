// Typed errors for bad input: every failure names the file, where in it (byte offset or
// line), and what was expected. Readers throw InputError; nothing else escapes them.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace omicron {

enum class InputErrorKind {
    CannotOpen,         // missing, unreadable (permissions), or an I/O error
    NotARegularFile,    // a directory, device or fifo
    EmptyFile,          // zero bytes
    UnknownFormat,      // neither extension nor magic bytes identify a supported format
    MalformedHeader,    // a header line or field that cannot be parsed
    UnsupportedFeature, // well-formed but not supported: LAZ, an unknown PLY type, ...
    Truncated,          // the file ends before the data its header declares
    CountMismatch,      // the file holds more data than its header declares, or counts disagree
    MalformedValue,     // a text value that is not a number, a wrong number of columns
    OutOfBounds,        // a point outside the bounding box the header declares
    NoPoints,           // a well-formed file without a single finite point
    CorruptData,        // compressed data (a LAZ chunk or chunk table) that does not decode
};

const char* toString(InputErrorKind kind);

// Where in a file an error was found.
struct InputLocation {
    enum class Unit { None, Byte, Line };
    Unit unit = Unit::None;
    std::uint64_t value = 0;

    static InputLocation none() { return {}; }
    static InputLocation byte(std::uint64_t offset) { return {Unit::Byte, offset}; }
    static InputLocation line(std::uint64_t number) { return {Unit::Line, number}; }
};

class InputError : public std::runtime_error {
public:
    // what() reads "PATH: byte N: DETAIL" (or "line N", or no location).
    InputError(InputErrorKind kind, std::string path, InputLocation location, std::string detail);

    InputErrorKind kind() const { return m_kind; }
    const std::string& path() const { return m_path; }
    const InputLocation& location() const { return m_location; }
    const std::string& detail() const { return m_detail; }

private:
    InputErrorKind m_kind;
    std::string m_path;
    InputLocation m_location;
    std::string m_detail;
};

} // namespace omicron
