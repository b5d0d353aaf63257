#include "io/input_error.hpp"

namespace omicron {

const char* toString(InputErrorKind kind) {
    switch (kind) {
    case InputErrorKind::CannotOpen: return "cannot open";
    case InputErrorKind::NotARegularFile: return "not a regular file";
    case InputErrorKind::EmptyFile: return "empty file";
    case InputErrorKind::UnknownFormat: return "unknown format";
    case InputErrorKind::MalformedHeader: return "malformed header";
    case InputErrorKind::UnsupportedFeature: return "unsupported feature";
    case InputErrorKind::Truncated: return "truncated";
    case InputErrorKind::CountMismatch: return "count mismatch";
    case InputErrorKind::MalformedValue: return "malformed value";
    case InputErrorKind::OutOfBounds: return "out of bounds";
    case InputErrorKind::NoPoints: return "no points";
    case InputErrorKind::CorruptData: return "corrupt data";
    }
    return "unknown error";
}

namespace {
std::string formatMessage(const std::string& path, const InputLocation& location,
                          const std::string& detail) {
    std::string message = path + ": ";
    switch (location.unit) {
    case InputLocation::Unit::Byte:
        message += "byte " + std::to_string(location.value) + ": ";
        break;
    case InputLocation::Unit::Line:
        message += "line " + std::to_string(location.value) + ": ";
        break;
    case InputLocation::Unit::None:
        break;
    }
    return message + detail;
}
} // namespace

InputError::InputError(InputErrorKind kind, std::string path, InputLocation location,
                       std::string detail)
    : std::runtime_error(formatMessage(path, location, detail)), m_kind(kind),
      m_path(std::move(path)), m_location(location), m_detail(std::move(detail)) {}

} // namespace omicron
