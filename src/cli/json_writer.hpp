// A minimal JSON writer for machine-readable output (info --json): objects, arrays, strings,
// numbers, booleans, written compactly on one line. Strings are escaped per RFC 8259, and bytes
// that are not valid UTF-8 (a file name can hold any bytes) become U+FFFD, so the output is
// always valid JSON.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace omicron::cli {

class JsonWriter {
public:
    JsonWriter& beginObject();
    JsonWriter& endObject();
    JsonWriter& beginArray();
    JsonWriter& endArray();
    JsonWriter& key(std::string_view name); // inside an object, before each value

    JsonWriter& value(std::string_view text);
    JsonWriter& value(const char* text) { return value(std::string_view(text)); }
    JsonWriter& value(double number); // shortest round-trip form; NaN and infinities: null
    JsonWriter& value(std::uint64_t number);
    JsonWriter& value(bool flag);

    const std::string& text() const { return m_text; }

private:
    void beforeValue();
    void open(char bracket);
    void close(char bracket);

    std::string m_text;
    std::vector<bool> m_containerHasElement; // one entry per open object/array
    bool m_afterKey = false;
};

// `text` as a JSON string literal, quotes included.
std::string jsonString(std::string_view text);

} // namespace omicron::cli
