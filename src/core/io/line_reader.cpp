#include "io/line_reader.hpp"

#include "io/input_error.hpp"

#include <cstring>

namespace omicron {

namespace {
constexpr std::size_t kBlockBytes = 1 << 20;
}

LineReader::LineReader(FileStream& stream, std::uint64_t firstLineNumber)
    : m_stream(stream), m_buffer(kBlockBytes + kMaxLineBytes),
      m_bufferOffset(stream.position()), m_nextLineNumber(firstLineNumber) {}

bool LineReader::refill() {
    if (m_eof) {
        return false;
    }
    // Keep the unconsumed tail (a partial line) at the front, then append a block.
    const std::size_t tail = m_end - m_begin;
    if (m_begin > 0) {
        std::memmove(m_buffer.data(), m_buffer.data() + m_begin, tail);
        m_bufferOffset += m_begin;
        m_begin = 0;
        m_end = tail;
    }
    const std::size_t room = m_buffer.size() - m_end;
    const std::size_t got = m_stream.read(m_buffer.data() + m_end, std::min(room, kBlockBytes));
    if (got == 0) {
        m_eof = true;
        return false;
    }
    m_end += got;
    return true;
}

bool LineReader::next(std::string_view& line) {
    std::size_t scanned = 0; // bytes of the current line already searched for '\n'
    for (;;) {
        const char* start = m_buffer.data() + m_begin + scanned;
        const auto* newline =
            static_cast<const char*>(std::memchr(start, '\n', m_end - m_begin - scanned));
        if (newline == nullptr && !m_eof) {
            if (m_end - m_begin > kMaxLineBytes) {
                throw InputError(InputErrorKind::MalformedValue, m_stream.path(),
                                 InputLocation::line(m_nextLineNumber),
                                 "expected a text line, found more than " +
                                     std::to_string(kMaxLineBytes) +
                                     " bytes without a line break");
            }
            scanned = m_end - m_begin;
            refill(); // moves the partial line to the front; sets m_eof at the end
            continue;
        }
        if (newline == nullptr && m_end == m_begin) {
            return false;
        }
        const std::size_t stop =
            newline != nullptr ? static_cast<std::size_t>(newline - m_buffer.data()) : m_end;
        std::size_t length = stop - m_begin;
        if (length > 0 && m_buffer[m_begin + length - 1] == '\r') {
            --length;
        }
        line = std::string_view(m_buffer.data() + m_begin, length);
        m_lineOffset = m_bufferOffset + m_begin;
        m_lineNumber = m_nextLineNumber++;
        m_begin = newline != nullptr ? stop + 1 : m_end;
        return true;
    }
}

} // namespace omicron
