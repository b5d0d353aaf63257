#include "io/record_block_reader.hpp"

#include "io/input_error.hpp"

#include <algorithm>

namespace omicron {

namespace {
// Blocks the helper may read ahead. More than two, so that a helper thread that the scheduler
// wakes late (a busy machine) rarely leaves the parser waiting.
constexpr std::size_t kSlots = 4;
} // namespace

RecordBlockReader::RecordBlockReader(FileStream& stream, std::uint64_t start,
                                     std::uint64_t recordBytes, std::uint64_t recordCount,
                                     std::size_t blockBytes, std::size_t paddingBytes)
    : m_stream(stream), m_start(start), m_recordBytes(std::max<std::uint64_t>(recordBytes, 1)),
      m_recordCount(recordCount),
      m_recordsPerBlock(std::max<std::size_t>(1, blockBytes / m_recordBytes)), m_slots(kSlots) {
    for (Slot& slot : m_slots) {
        slot.bytes.resize(m_recordsPerBlock * m_recordBytes + paddingBytes);
    }
    m_stream.seek(m_start);
    m_helper = std::thread([this] { produce(); });
}

RecordBlockReader::~RecordBlockReader() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
    }
    m_changed.notify_all();
    m_helper.join();
}

void RecordBlockReader::produce() {
    std::uint64_t nextIndex = 0;
    std::size_t slotIndex = 0;
    while (nextIndex < m_recordCount) {
        Slot& slot = m_slots[slotIndex];
        {
            std::unique_lock lock(m_mutex);
            m_changed.wait(lock, [&] { return m_stop || !slot.filled; });
            if (m_stop) {
                return;
            }
        }
        // The slot is free: the consumer neither reads it nor touches it until `filled`.
        const std::size_t records = static_cast<std::size_t>(
            std::min<std::uint64_t>(m_recordsPerBlock, m_recordCount - nextIndex));
        const std::size_t bytes = records * static_cast<std::size_t>(m_recordBytes);
        std::size_t got = 0;
        std::exception_ptr error;
        try {
            got = m_stream.read(slot.bytes.data(), bytes);
        } catch (...) {
            error = std::current_exception();
        }
        {
            std::lock_guard lock(m_mutex);
            slot.count = got / static_cast<std::size_t>(m_recordBytes);
            slot.firstIndex = nextIndex;
            slot.shortRead = got != bytes;
            slot.filled = true;
            m_error = error;
        }
        m_changed.notify_all();
        if (error || slot.shortRead) {
            return;
        }
        nextIndex += records;
        slotIndex = (slotIndex + 1) % kSlots;
    }
}

bool RecordBlockReader::next(Block& block) {
    std::unique_lock lock(m_mutex);
    if (m_holdingSlot) {
        m_slots[m_consumerSlot].filled = false;
        m_consumerSlot = (m_consumerSlot + 1) % kSlots;
        m_holdingSlot = false;
        m_changed.notify_all();
    }
    if (m_consumedRecords == m_recordCount) {
        return false;
    }
    Slot& slot = m_slots[m_consumerSlot];
    m_changed.wait(lock, [&] { return slot.filled; });
    if (slot.count == 0 && m_error) {
        std::rethrow_exception(m_error);
    }
    if (slot.count == 0 && slot.shortRead) {
        const std::uint64_t missing = slot.firstIndex;
        throw InputError(InputErrorKind::Truncated, m_stream.path(),
                         InputLocation::byte(m_start + missing * m_recordBytes),
                         "expected record " + std::to_string(missing) + " of " +
                             std::to_string(m_recordCount) + " (" + std::to_string(m_recordBytes) +
                             " bytes each from byte " + std::to_string(m_start) +
                             "), but the file ends at byte " + std::to_string(m_stream.size()));
    }
    // A short block still delivers its whole records; the next call reports what is missing.
    if (slot.shortRead) {
        Slot& other = m_slots[(m_consumerSlot + 1) % kSlots];
        other.firstIndex = slot.firstIndex + slot.count;
        other.count = 0;
        other.shortRead = slot.shortRead;
        other.filled = true;
    }
    block.records = slot.bytes.data();
    block.count = slot.count;
    block.firstIndex = slot.firstIndex;
    m_consumedRecords += slot.count;
    m_holdingSlot = true;
    return true;
}

} // namespace omicron
