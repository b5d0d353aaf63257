// An append-only array whose elements never move, readable while one thread appends.
//
// Elements live in fixed-size chunks; the table of chunk pointers is allocated once, for the
// capacity given at construction, so appending never reallocates anything a reader may be
// looking at (std::vector moves its elements, std::deque reallocates its map). The arena does
// no synchronisation of its own: the writer publishes a count with a release store (see
// Hierarchy), and a reader only indexes below a count it loaded with acquire.
//
// Chunks are allocated uninitialised: every element is written whole before it is published,
// so zeroing a chunk first would only double the writes, on the writer's thread, where the
// elements themselves may be written by many (extend()/slot()). Elements are therefore plain
// data (trivially copyable and destructible: implicitly created by the allocation).
#pragma once

#include <cassert>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>

namespace omicron {

template <typename T, std::size_t ChunkElements> class ChunkedArena {
    static_assert(ChunkElements > 0 && (ChunkElements & (ChunkElements - 1)) == 0,
                  "chunk size must be a power of two (index split by shift and mask)");
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                  "elements live in uninitialised chunks");

    struct ChunkDeleter {
        void operator()(T* chunk) const { ::operator delete(chunk, std::align_val_t{alignof(T)}); }
    };
    using Chunk = std::unique_ptr<T, ChunkDeleter>;
    static Chunk allocateChunk() {
        return Chunk(static_cast<T*>(
            ::operator new(ChunkElements * sizeof(T), std::align_val_t{alignof(T)})));
    }

public:
    explicit ChunkedArena(std::size_t capacity)
        : m_capacity(capacity),
          m_chunks(std::make_unique<Chunk[]>((capacity + ChunkElements - 1) / ChunkElements)) {}

    ChunkedArena(const ChunkedArena&) = delete;
    ChunkedArena& operator=(const ChunkedArena&) = delete;

    std::size_t capacity() const { return m_capacity; }
    // Writer side: elements appended so far (readers use the published count instead).
    std::size_t size() const { return m_size; }

    // Writer only. Returns the new element's index.
    std::size_t push_back(const T& value) {
        const std::size_t index = extend(1);
        slot(index) = value;
        return index;
    }

    // Writer only: appends `count` elements, not yet written (allocating their chunks), and
    // returns the first one's index. The writer may have them filled whole through slot() by
    // other threads, provided the filling happens-before the count that covers them is
    // published.
    std::size_t extend(std::size_t count) {
        assert(count <= m_capacity - m_size);
        const std::size_t first = m_size;
        for (std::size_t chunk = (first + ChunkElements - 1) / ChunkElements;
             chunk * ChunkElements < first + count; ++chunk) {
            m_chunks[chunk] = allocateChunk();
        }
        m_size += count;
        return first;
    }
    // An element appended but not yet published, to fill.
    T& slot(std::size_t index) {
        assert(index < m_size);
        return m_chunks[index / ChunkElements].get()[index % ChunkElements];
    }

    const T& operator[](std::size_t index) const {
        return m_chunks[index / ChunkElements].get()[index % ChunkElements];
    }

    std::size_t bytesAllocated() const {
        // Chunks exist exactly for the elements appended.
        return (m_size + ChunkElements - 1) / ChunkElements * ChunkElements * sizeof(T) +
               (m_capacity + ChunkElements - 1) / ChunkElements * sizeof(Chunk);
    }

private:
    std::size_t m_capacity;
    std::size_t m_size = 0;
    std::unique_ptr<Chunk[]> m_chunks;
};

} // namespace omicron
