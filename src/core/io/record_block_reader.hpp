// Reads an array of fixed-size records from a file in blocks of whole records, one block ahead
// as a oneTBB task: the kernel's copy of the next block overlaps the parsing of this one, on a
// worker thread where one is free (the caller reads it itself when none is). A thread of its
// own per reader made the 24.2 M-point LAS read phase 0.03 s slower than the task: one more
// thread for the two cores to share with the parser, the sorter and the workers.
//
// A block of 512 KiB or more sits on huge pages where they pay off: LAS's two 1 MiB slots on
// small pages took 6 ms of first touches before the first record was parsed on the test VM
// (3 ms per MiB, against 0.08 ms on huge pages).
#pragma once

#include "io/file_stream.hpp"
#include "points/huge_page_buffer.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <tbb/task_group.h>

namespace omicron {

class RecordBlockReader {
public:
    struct Block {
        std::uint8_t* records = nullptr; // the caller's to change in place until next()
        std::size_t count = 0;        // whole records in this block
        std::uint64_t firstIndex = 0; // index of records[0] in the array
    };

    // Reads `recordCount` records of `recordBytes` starting at byte `start` of `stream`, which
    // the reader uses until destruction. Every block is followed by `paddingBytes` readable
    // bytes, so that parsers may load a few bytes past a record's last field.
    RecordBlockReader(FileStream& stream, std::uint64_t start, std::uint64_t recordBytes,
                      std::uint64_t recordCount, std::size_t blockBytes, std::size_t paddingBytes);
    ~RecordBlockReader(); // waits for the read in flight, also when the caller stops early
    RecordBlockReader(const RecordBlockReader&) = delete;
    RecordBlockReader& operator=(const RecordBlockReader&) = delete;

    // The next block, valid until the following call; false after the last record. Throws
    // Truncated (naming the first missing record and its byte) when the file ends early, and
    // rethrows read errors.
    bool next(Block& block);

private:
    struct Slot {
        HugePageArray<std::uint8_t> bytes; // uninitialised but the padding
        std::size_t count = 0;        // whole records read
        std::uint64_t firstIndex = 0; // of its first record
        bool shortRead = false;       // the file ended inside this block
    };

    // Starts reading the block of record `firstIndex` into `slot` (none is in flight).
    void startRead(Slot& slot, std::uint64_t firstIndex);

    FileStream& m_stream;
    std::uint64_t m_start;
    std::uint64_t m_recordBytes;
    std::uint64_t m_recordCount;
    std::size_t m_recordsPerBlock;
    std::array<Slot, 2> m_slots; // one the caller parses, one being read
    std::size_t m_nextSlot = 0;  // the slot the next block is read into
    bool m_ended = false;        // the last block was handed out, or the file ended early
    tbb::task_group m_read;
};

} // namespace omicron
