#include "io/record_block_reader.hpp"

#include "io/input_error.hpp"

#include <algorithm>

namespace omicron {

RecordBlockReader::RecordBlockReader(FileStream& stream, std::uint64_t start,
                                     std::uint64_t recordBytes, std::uint64_t recordCount,
                                     std::size_t blockBytes, std::size_t paddingBytes)
    : m_stream(stream), m_start(start), m_recordBytes(std::max<std::uint64_t>(recordBytes, 1)),
      m_recordCount(recordCount),
      m_recordsPerBlock(std::max<std::size_t>(1, blockBytes / m_recordBytes)) {
    const std::size_t blockSize = static_cast<std::size_t>(
        std::min<std::uint64_t>(m_recordsPerBlock, m_recordCount) * m_recordBytes);
    const PageSize pages = blockSize >= kHugePageBytes / 4 ? PageSize::Huge : PageSize::Small;
    for (Slot& slot : m_slots) {
        slot.bytes = HugePageArray<std::uint8_t>(blockSize + paddingBytes, pages);
        std::fill_n(slot.bytes.data() + blockSize, paddingBytes, std::uint8_t{0});
    }
    m_stream.seek(m_start);
    if (m_recordCount == 0) {
        m_ended = true;
        return;
    }
    startRead(m_slots[0], 0);
}

RecordBlockReader::~RecordBlockReader() {
    try {
        m_read.wait(); // the read in flight, if any
    } catch (...) { // the caller stopped early or is unwinding from its own error
    }
}

void RecordBlockReader::startRead(Slot& slot, std::uint64_t firstIndex) {
    const auto records = static_cast<std::size_t>(
        std::min<std::uint64_t>(m_recordsPerBlock, m_recordCount - firstIndex));
    const std::size_t bytes = records * static_cast<std::size_t>(m_recordBytes);
    slot.firstIndex = firstIndex;
    slot.count = 0;
    slot.shortRead = false;
    // The slot and the stream are the task's until wait(): the caller parses the other slot.
    m_read.run([this, &slot, bytes] {
        const std::size_t got = m_stream.read(slot.bytes.data(), bytes);
        slot.count = got / static_cast<std::size_t>(m_recordBytes);
        slot.shortRead = got != bytes;
    });
}

bool RecordBlockReader::next(Block& block) {
    if (m_ended) {
        return false;
    }
    Slot& slot = m_slots[m_nextSlot];
    try {
        m_read.wait(); // rethrows the read's error
    } catch (...) {
        m_ended = true;
        throw;
    }
    if (slot.count == 0 && slot.shortRead) {
        m_ended = true;
        const std::uint64_t missing = slot.firstIndex;
        throw InputError(InputErrorKind::Truncated, m_stream.path(),
                         InputLocation::byte(m_start + missing * m_recordBytes),
                         "expected record " + std::to_string(missing) + " of " +
                             std::to_string(m_recordCount) + " (" + std::to_string(m_recordBytes) +
                             " bytes each from byte " + std::to_string(m_start) +
                             "), but the file ends at byte " + std::to_string(m_stream.size()));
    }
    const std::uint64_t following = slot.firstIndex + slot.count;
    m_nextSlot = 1 - m_nextSlot;
    if (slot.shortRead) {
        // A short block still delivers its whole records; the next call reports what is
        // missing (an empty short read).
        Slot& empty = m_slots[m_nextSlot];
        empty.firstIndex = following;
        empty.count = 0;
        empty.shortRead = true;
    } else if (following < m_recordCount) {
        startRead(m_slots[m_nextSlot], following); // the block the caller released
    } else {
        m_ended = true;
    }
    block.records = slot.bytes.data();
    block.count = slot.count;
    block.firstIndex = slot.firstIndex;
    return true;
}

} // namespace omicron
