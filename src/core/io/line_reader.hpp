// Line-by-line reading of text (ASCII PLY bodies, XYZ files) with bounded memory, counting
// lines and bytes so errors can say where they are.
#pragma once

#include "io/file_stream.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace omicron {

class LineReader {
public:
    // Starts at the stream's current position; `firstLineNumber` is the 1-based number of the
    // line that starts there.
    explicit LineReader(FileStream& stream, std::uint64_t firstLineNumber = 1);

    // Next line without its terminator ("\n", "\r\n" or "\r" before "\n"); false at the end.
    // The view stays valid until the next call. Lines longer than kMaxLineBytes throw
    // MalformedValue (a binary file read as text must not eat all memory).
    bool next(std::string_view& line);

    std::uint64_t lineNumber() const { return m_lineNumber; }      // of the last line returned
    std::uint64_t lineOffset() const { return m_lineOffset; }      // its byte offset

    static constexpr std::size_t kMaxLineBytes = 1 << 20;

private:
    bool refill();

    FileStream& m_stream;
    std::vector<char> m_buffer;
    std::size_t m_begin = 0; // first unconsumed byte in m_buffer
    std::size_t m_end = 0;   // one past the last valid byte
    std::uint64_t m_bufferOffset = 0; // file offset of m_buffer[0]
    std::uint64_t m_lineNumber = 0;
    std::uint64_t m_lineOffset = 0;
    std::uint64_t m_nextLineNumber;
    bool m_eof = false;
};

} // namespace omicron
