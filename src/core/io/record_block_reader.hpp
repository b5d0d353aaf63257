// Reads an array of fixed-size records from a file in blocks of whole records, one block ahead
// on a helper thread: the kernel's copy of the next block overlaps the parsing of this one,
// which is what lets a binary reader keep up with raw read() throughput.
#pragma once

#include "io/file_stream.hpp"

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace omicron {

class RecordBlockReader {
public:
    struct Block {
        const std::uint8_t* records = nullptr;
        std::size_t count = 0;        // whole records in this block
        std::uint64_t firstIndex = 0; // index of records[0] in the array
    };

    // Reads `recordCount` records of `recordBytes` starting at byte `start` of `stream`, which
    // the helper thread owns until destruction. Every block is followed by `paddingBytes`
    // readable bytes, so that parsers may load a few bytes past a record's last field.
    RecordBlockReader(FileStream& stream, std::uint64_t start, std::uint64_t recordBytes,
                      std::uint64_t recordCount, std::size_t blockBytes, std::size_t paddingBytes);
    ~RecordBlockReader(); // stops and joins the helper, also when the caller stops early
    RecordBlockReader(const RecordBlockReader&) = delete;
    RecordBlockReader& operator=(const RecordBlockReader&) = delete;

    // The next block, valid until the following call; false after the last record. Throws
    // Truncated (naming the first missing record and its byte) when the file ends early, and
    // rethrows read errors from the helper thread.
    bool next(Block& block);

private:
    struct Slot {
        std::vector<std::uint8_t> bytes;
        std::size_t count = 0;
        std::uint64_t firstIndex = 0;
        bool filled = false;
        bool shortRead = false; // the file ended inside this block
    };

    void produce();

    FileStream& m_stream;
    std::uint64_t m_start;
    std::uint64_t m_recordBytes;
    std::uint64_t m_recordCount;
    std::size_t m_recordsPerBlock;
    std::uint64_t m_consumedRecords = 0;
    std::vector<Slot> m_slots; // a ring: the helper fills ahead while the caller parses
    std::size_t m_consumerSlot = 0;
    bool m_holdingSlot = false; // the caller still reads m_slots[m_consumerSlot]

    std::mutex m_mutex;
    std::condition_variable m_changed;
    bool m_stop = false;
    std::exception_ptr m_error;
    std::thread m_helper;
};

} // namespace omicron
