// A byte buffer for data that is written whole before it is read (compressed bytes read from a
// file, records a decoder fills): grown without zeroing and kept from one use to the next.
// A std::vector would zero every byte it grows by (28.6 MB of LAZ records: about 3 ms on the
// decoding's serial path) and, made afresh per batch, fault in new pages each time (a batch
// larger than glibc's 32 MiB mmap threshold is always new memory).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace omicron {

class ScratchBytes {
public:
    // `bytes` bytes holding whatever was there before (nothing meaningful: the caller writes
    // them first). Pointers from an earlier take() stay valid unless this one grows the buffer.
    std::span<std::uint8_t> take(std::size_t bytes) {
        if (bytes > m_capacity) {
            m_bytes.reset(); // the old buffer goes before the new one comes: no two at once
            m_capacity = 0;
            m_bytes = std::make_unique_for_overwrite<std::uint8_t[]>(bytes);
            m_capacity = bytes;
        }
        return {m_bytes.get(), bytes};
    }

private:
    std::unique_ptr<std::uint8_t[]> m_bytes;
    std::size_t m_capacity = 0;
};

} // namespace omicron
