#include "io/ply/ply_header.hpp"

#include "io/decimal_text.hpp"
#include "io/input_error.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>

namespace omicron {

namespace {

// Real headers are a few hundred bytes; the limit keeps a binary file that merely starts with
// "ply" from being scanned whole for a line break.
constexpr std::size_t kMaxHeaderBytes = 1 << 20;

struct TypeSpelling {
    std::string_view name;
    PlyScalarType type;
};

constexpr TypeSpelling kTypeSpellings[] = {
    {"char", PlyScalarType::Int8},      {"int8", PlyScalarType::Int8},
    {"uchar", PlyScalarType::UInt8},    {"uint8", PlyScalarType::UInt8},
    {"short", PlyScalarType::Int16},    {"int16", PlyScalarType::Int16},
    {"ushort", PlyScalarType::UInt16},  {"uint16", PlyScalarType::UInt16},
    {"int", PlyScalarType::Int32},      {"int32", PlyScalarType::Int32},
    {"uint", PlyScalarType::UInt32},    {"uint32", PlyScalarType::UInt32},
    {"float", PlyScalarType::Float32},  {"float32", PlyScalarType::Float32},
    {"double", PlyScalarType::Float64}, {"float64", PlyScalarType::Float64},
};

std::optional<PlyScalarType> parseType(std::string_view name) {
    for (const TypeSpelling& spelling : kTypeSpellings) {
        if (spelling.name == name) {
            return spelling.type;
        }
    }
    return std::nullopt;
}

bool isIntegerType(PlyScalarType type) {
    return type != PlyScalarType::Float32 && type != PlyScalarType::Float64;
}

std::vector<std::string_view> splitWords(std::string_view line) {
    std::vector<std::string_view> words;
    std::size_t position = 0;
    while (position < line.size()) {
        while (position < line.size() && (line[position] == ' ' || line[position] == '\t')) {
            ++position;
        }
        const std::size_t start = position;
        while (position < line.size() && line[position] != ' ' && line[position] != '\t') {
            ++position;
        }
        if (position > start) {
            words.push_back(line.substr(start, position - start));
        }
    }
    return words;
}

std::optional<double> parseDouble(std::string_view text) {
    double value = 0.0;
    if (!parseDecimal(text, value) || !std::isfinite(value)) {
        return std::nullopt;
    }
    return value;
}

class HeaderParser {
public:
    HeaderParser(const std::string& path, std::string_view text, bool fileEndsInText)
        : m_path(path), m_text(text), m_fileEndsInText(fileEndsInText) {}

    PlyHeader parse();

private:
    // The next line without its terminator; false once `end_header` cannot follow.
    std::string_view nextLine();
    [[noreturn]] void fail(InputErrorKind kind, const std::string& detail) const {
        throw InputError(kind, m_path, InputLocation::line(m_lineNumber), detail);
    }
    void parseFormat(const std::vector<std::string_view>& words, std::string_view line);
    void parseComment(const std::vector<std::string_view>& words, std::string_view line);
    void parseElement(const std::vector<std::string_view>& words, std::string_view line);
    void parseProperty(const std::vector<std::string_view>& words, std::string_view line);
    PlyScalarType typeOrFail(std::string_view name) const;
    void checkElementSize() const;

    const std::string& m_path;
    std::string_view m_text;
    bool m_fileEndsInText;
    std::size_t m_position = 0;
    std::uint64_t m_lineNumber = 0;
    bool m_sawFormat = false;
    PlyHeader m_header;
};

std::string_view HeaderParser::nextLine() {
    const std::size_t newline = m_text.find('\n', m_position);
    ++m_lineNumber;
    if (newline == std::string_view::npos) {
        // A last line without a terminator is fine only when the file really ends there.
        if (m_fileEndsInText && m_position < m_text.size()) {
            std::string_view line = m_text.substr(m_position);
            m_position = m_text.size();
            if (line.back() == '\r') {
                line.remove_suffix(1);
            }
            return line;
        }
        if (m_fileEndsInText) {
            fail(InputErrorKind::Truncated,
                 "expected more header lines ending with 'end_header', but the file ends at "
                 "byte " +
                     std::to_string(m_text.size()));
        }
        fail(InputErrorKind::MalformedHeader,
             "expected 'end_header' within the first " + std::to_string(kMaxHeaderBytes) +
                 " bytes; the header is too long or the file is not a PLY file");
    }
    std::string_view line = m_text.substr(m_position, newline - m_position);
    m_position = newline + 1;
    if (!line.empty() && line.back() == '\r') {
        line.remove_suffix(1);
    }
    return line;
}

PlyScalarType HeaderParser::typeOrFail(std::string_view name) const {
    if (const std::optional<PlyScalarType> type = parseType(name)) {
        return *type;
    }
    fail(InputErrorKind::UnsupportedFeature,
         "unknown property type '" + std::string(name) +
             "'; expected char, uchar, short, ushort, int, uint, float, double (or int8, uint8, "
             "int16, uint16, int32, uint32, float32, float64)");
}

void HeaderParser::parseFormat(const std::vector<std::string_view>& words, std::string_view line) {
    if (m_sawFormat) {
        fail(InputErrorKind::MalformedHeader,
             "found a second 'format' line '" + std::string(line) + "'; expected one");
    }
    if (words.size() != 3) {
        fail(InputErrorKind::MalformedHeader,
             "expected 'format ascii|binary_little_endian|binary_big_endian 1.0', found '" +
                 std::string(line) + "'");
    }
    if (words[1] == "ascii") {
        m_header.format = CloudFormat::PlyAscii;
    } else if (words[1] == "binary_little_endian") {
        m_header.format = CloudFormat::PlyBinaryLittleEndian;
    } else if (words[1] == "binary_big_endian") {
        m_header.format = CloudFormat::PlyBinaryBigEndian;
    } else {
        fail(InputErrorKind::UnsupportedFeature,
             "unknown PLY format '" + std::string(words[1]) +
                 "'; expected ascii, binary_little_endian or binary_big_endian");
    }
    const std::optional<double> version = parseDouble(words[2]);
    if (!version || *version != 1.0) {
        fail(InputErrorKind::UnsupportedFeature,
             "unsupported PLY version '" + std::string(words[2]) + "'; expected 1.0");
    }
    m_sawFormat = true;
}

void HeaderParser::parseComment(const std::vector<std::string_view>& words, std::string_view line) {
    if (words.size() < 2 || words[1] != "offset") {
        return;
    }
    // The ../shared/data convention: "comment offset X Y Z [free text]".
    const auto number = [&](std::size_t index) {
        return index < words.size() ? parseDouble(words[index]) : std::nullopt;
    };
    const std::optional<double> x = number(2), y = number(3), z = number(4);
    if (!x || !y || !z) {
        fail(InputErrorKind::MalformedHeader,
             "expected 'comment offset X Y Z' with three finite numbers, found '" +
                 std::string(line) + "'");
    }
    if (m_header.hasOffset) {
        fail(InputErrorKind::MalformedHeader,
             "found a second 'comment offset' line; expected at most one");
    }
    m_header.hasOffset = true;
    m_header.offset = {*x, *y, *z};
}

void HeaderParser::checkElementSize() const {
    // count * bytes must be representable, or every later size computation would wrap.
    const PlyElement& element = m_header.elements.back();
    const std::uint64_t bytes = std::max<std::uint64_t>(element.minimumBinaryBytes(), 1);
    if (element.count > std::numeric_limits<std::uint64_t>::max() / bytes) {
        fail(InputErrorKind::MalformedHeader,
             "element '" + element.name + "' declares " + std::to_string(element.count) +
                 " records of at least " + std::to_string(bytes) +
                 " bytes, which overflows a 64-bit size; expected a plausible count");
    }
}

void HeaderParser::parseElement(const std::vector<std::string_view>& words, std::string_view line) {
    if (!m_header.elements.empty()) {
        checkElementSize();
    }
    if (words.size() != 3) {
        fail(InputErrorKind::MalformedHeader,
             "expected 'element NAME COUNT', found '" + std::string(line) + "'");
    }
    const std::string_view countText = words[2];
    if (!countText.empty() && countText.front() == '-') {
        fail(InputErrorKind::MalformedHeader,
             "element '" + std::string(words[1]) + "' has a negative count " +
                 std::string(countText) + "; expected a count >= 0");
    }
    std::uint64_t count = 0;
    const auto [end, error] =
        std::from_chars(countText.data(), countText.data() + countText.size(), count);
    if (error == std::errc::result_out_of_range) {
        fail(InputErrorKind::MalformedHeader, "element '" + std::string(words[1]) + "' count " +
                                                  std::string(countText) +
                                                  " is too large; expected a count below 2^64");
    }
    if (error != std::errc() || end != countText.data() + countText.size()) {
        fail(InputErrorKind::MalformedHeader,
             "expected 'element NAME COUNT' with a whole-number count, found '" +
                 std::string(line) + "'");
    }
    for (const PlyElement& earlier : m_header.elements) {
        if (earlier.name == words[1]) {
            fail(InputErrorKind::MalformedHeader,
                 "found a second 'element " + earlier.name + "' (the first is on line " +
                     std::to_string(earlier.headerLine) + "); expected unique element names");
        }
    }
    PlyElement element;
    element.name = std::string(words[1]);
    element.count = count;
    element.headerLine = m_lineNumber;
    m_header.elements.push_back(std::move(element));
}

void HeaderParser::parseProperty(const std::vector<std::string_view>& words,
                                 std::string_view line) {
    if (m_header.elements.empty()) {
        fail(InputErrorKind::MalformedHeader, "found '" + std::string(line) +
                                                  "' before any 'element' line; expected "
                                                  "'element NAME COUNT' first");
    }
    PlyProperty property;
    if (words.size() == 5 && words[1] == "list") {
        property.isList = true;
        property.countType = typeOrFail(words[2]);
        if (!isIntegerType(property.countType)) {
            fail(InputErrorKind::MalformedHeader,
                 "list count type '" + std::string(words[2]) +
                     "' is not an integer type; expected e.g. 'property list uchar int "
                     "vertex_indices'");
        }
        property.type = typeOrFail(words[3]);
        property.name = std::string(words[4]);
    } else if (words.size() == 3 && words[1] != "list") {
        property.type = typeOrFail(words[1]);
        property.name = std::string(words[2]);
    } else {
        fail(InputErrorKind::MalformedHeader,
             "expected 'property TYPE NAME' or 'property list COUNT_TYPE ITEM_TYPE NAME', "
             "found '" +
                 std::string(line) + "'");
    }
    PlyElement& element = m_header.elements.back();
    if (element.findProperty(property.name) >= 0) {
        fail(InputErrorKind::MalformedHeader, "element '" + element.name +
                                                  "' has a second property '" + property.name +
                                                  "'; expected unique property names");
    }
    element.properties.push_back(std::move(property));
}

PlyHeader HeaderParser::parse() {
    if (m_text.substr(0, 3) != "ply" ||
        splitWords(nextLine()) != std::vector<std::string_view>{"ply"}) {
        m_lineNumber = 1;
        fail(InputErrorKind::UnknownFormat, "expected the first line to be 'ply' (the PLY magic)");
    }
    for (;;) {
        const std::string_view line = nextLine();
        const std::vector<std::string_view> words = splitWords(line);
        if (words.empty()) {
            continue;
        }
        const std::string_view keyword = words[0];
        if (keyword == "comment" || keyword == "obj_info") {
            parseComment(words, line);
            continue;
        }
        if (keyword == "format") {
            parseFormat(words, line);
            continue;
        }
        if (!m_sawFormat) {
            fail(InputErrorKind::MalformedHeader,
                 "expected 'format ascii|binary_little_endian|binary_big_endian 1.0' after "
                 "'ply', found '" +
                     std::string(line) + "'");
        }
        if (keyword == "element") {
            parseElement(words, line);
        } else if (keyword == "property") {
            parseProperty(words, line);
        } else if (keyword == "end_header" && words.size() == 1) {
            if (!m_header.elements.empty()) {
                checkElementSize();
            }
            m_header.endHeaderLine = m_lineNumber;
            m_header.bodyFirstLine = m_lineNumber + 1;
            m_header.bodyOffset = m_position;
            return std::move(m_header);
        } else {
            fail(InputErrorKind::MalformedHeader,
                 "expected a 'comment', 'obj_info', 'element', 'property' or 'end_header' "
                 "line, found '" +
                     std::string(line) + "'");
        }
    }
}

} // namespace

std::size_t plyScalarBytes(PlyScalarType type) {
    switch (type) {
    case PlyScalarType::Int8:
    case PlyScalarType::UInt8:
        return 1;
    case PlyScalarType::Int16:
    case PlyScalarType::UInt16:
        return 2;
    case PlyScalarType::Int32:
    case PlyScalarType::UInt32:
    case PlyScalarType::Float32:
        return 4;
    case PlyScalarType::Float64:
        return 8;
    }
    return 0;
}

const char* plyScalarName(PlyScalarType type) {
    switch (type) {
    case PlyScalarType::Int8:
        return "char";
    case PlyScalarType::UInt8:
        return "uchar";
    case PlyScalarType::Int16:
        return "short";
    case PlyScalarType::UInt16:
        return "ushort";
    case PlyScalarType::Int32:
        return "int";
    case PlyScalarType::UInt32:
        return "uint";
    case PlyScalarType::Float32:
        return "float";
    case PlyScalarType::Float64:
        return "double";
    }
    return "unknown";
}

bool PlyElement::hasLists() const {
    return std::any_of(properties.begin(), properties.end(),
                       [](const PlyProperty& property) { return property.isList; });
}

std::uint64_t PlyElement::recordBytes() const {
    std::uint64_t bytes = 0;
    for (const PlyProperty& property : properties) {
        bytes += plyScalarBytes(property.type);
    }
    return bytes;
}

std::uint64_t PlyElement::minimumBinaryBytes() const {
    std::uint64_t bytes = 0;
    for (const PlyProperty& property : properties) {
        bytes += plyScalarBytes(property.isList ? property.countType : property.type);
    }
    return bytes;
}

int PlyElement::findProperty(std::string_view propertyName) const {
    for (std::size_t index = 0; index < properties.size(); ++index) {
        if (properties[index].name == propertyName) {
            return static_cast<int>(index);
        }
    }
    return -1;
}

PlyHeader parsePlyHeader(FileStream& stream) {
    const std::size_t readable =
        static_cast<std::size_t>(std::min<std::uint64_t>(stream.size(), kMaxHeaderBytes));
    std::string text(readable, '\0');
    stream.seek(0);
    text.resize(stream.read(text.data(), readable));
    return HeaderParser(stream.path(), text, text.size() == stream.size()).parse();
}

} // namespace omicron
