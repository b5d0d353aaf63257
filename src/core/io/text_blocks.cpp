#include "io/text_blocks.hpp"

#include "io/input_error.hpp"
#include "io/line_reader.hpp"

#include <algorithm>
#include <cstring>
#include <string>

namespace omicron {

TextBlockReader::TextBlockReader(const FileStream& stream, std::uint64_t offset,
                                 std::uint64_t firstLine)
    : m_stream(stream), m_offset(offset), m_line(firstLine) {}

bool TextBlockReader::next(TextBlock& block) {
    block.bytes.assign(m_carry.begin(), m_carry.end());
    block.offset = m_offset - m_carry.size();
    block.firstLine = m_line;
    m_carry.clear();
    for (;;) {
        const std::size_t before = block.bytes.size();
        block.bytes.resize(before + kBlockBytes);
        const std::size_t got = m_stream.readAt(m_offset, block.bytes.data() + before, kBlockBytes);
        block.bytes.resize(before + got);
        m_offset += got;
        if (got == 0) { // the end: what is left is the last line, without a line break
            block.lines = 0;
            return !block.bytes.empty();
        }
        // No line break before `before`: the block's first line ends in what was just read,
        // if anywhere.
        const char* const data = block.bytes.data();
        const auto* first = static_cast<const char*>(std::memchr(data + before, '\n', got));
        const std::size_t firstLineBytes =
            first != nullptr ? static_cast<std::size_t>(first - data) : block.bytes.size();
        if (firstLineBytes > LineReader::kMaxLineBytes) {
            throw InputError(
                InputErrorKind::MalformedValue, m_stream.path(), InputLocation::line(m_line),
                "expected a text line, found more than " +
                    std::to_string(LineReader::kMaxLineBytes) + " bytes without a line break");
        }
        if (first != nullptr) {
            const auto* last =
                static_cast<const char*>(::memrchr(first, '\n', data + block.bytes.size() - first));
            const std::size_t keep = static_cast<std::size_t>(last - data) + 1;
            m_carry.assign(data + keep, data + block.bytes.size());
            block.bytes.resize(keep);
            break;
        }
    }
    block.lines =
        static_cast<std::uint64_t>(std::count(block.bytes.begin(), block.bytes.end(), '\n'));
    m_line += block.lines;
    return true;
}

bool TextBlockLines::next(std::string_view& line) {
    const std::size_t size = m_block.bytes.size();
    if (m_at >= size) {
        return false;
    }
    const char* const data = m_block.bytes.data();
    const auto* newline = static_cast<const char*>(std::memchr(data + m_at, '\n', size - m_at));
    const std::size_t stop = newline != nullptr ? static_cast<std::size_t>(newline - data) : size;
    std::size_t length = stop - m_at;
    if (length > 0 && data[m_at + length - 1] == '\r') {
        --length;
    }
    line = std::string_view(data + m_at, length);
    m_lineStart = m_at;
    m_lineNumber = m_nextLine++;
    m_at = newline != nullptr ? stop + 1 : size;
    return true;
}

} // namespace omicron
