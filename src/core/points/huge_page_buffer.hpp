// Large, write-once arrays backed by transparent huge pages where the kernel allows them.
//
// A build writes and scans tens of megabytes: with 4 KiB pages every page costs a fault on
// first touch and scans that stride through memory miss the TLB (measured: a skip-ahead scan
// of 4.8M sorted positions runs 1.35x faster on huge pages). An array aligned to 2 MiB and
// advised MADV_HUGEPAGE takes one fault and one TLB entry per 2 MiB instead. Where huge
// pages are off ("never"), or cost more than they save (a hypervisor that takes free memory
// back: points/huge_page_policy.hpp), this is an ordinary aligned allocation on small pages.
// The elements are left uninitialised: the owners write before they publish.
//
// A cloud paged in on demand (a large .omh) wants the opposite: address space for every point,
// memory only for the nodes loaded, given back when a node is evicted. Its arrays ask for
// small pages (PageSize::Small): a huge page would turn the first write of a 100-point node
// into 2 MiB resident, and releasing part of one splits it (points/resident_pages.hpp).
#pragma once

#include "points/huge_page_policy.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <sys/mman.h>
#include <type_traits>

namespace omicron {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

// The bytes an array of `bytes` takes: a whole number of huge pages.
constexpr std::size_t hugePageArrayBytes(std::size_t bytes) {
    return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

enum class PageSize {
    Huge,  // written once, scanned often: fewer faults and TLB misses
    Small, // written and released piecemeal (ResidentPages)
};

// A sorted cloud larger than the memory budget keeps its arrays in a scratch file instead
// (points/file_backed_memory.hpp): the same addresses, but the kernel may write the pages
// back and the owner drops them from its resident set (dropResident), and reading them again
// faults them back in from the page cache or the file.
struct FileBacking {
    std::string folder; // where the unnamed scratch file lives (removed when unmapped)
};

// Maps `bytes` of a new unnamed file in `folder` (space reserved up front) and sets `fd` to
// its descriptor, kept open for writeScratchFile; throws std::runtime_error naming the folder
// and the bytes when it cannot.
void* mapScratchFile(const std::string& folder, std::size_t bytes, int& fd);
void unmapScratchFile(void* memory, std::size_t bytes, int fd);
// Writes `bytes` at `offset` of the scratch file with `fd` through the page cache; the
// mapping sees them at once. Throws std::runtime_error (an I/O error: the space is reserved).
void writeScratchFile(int fd, std::uint64_t offset, const void* data, std::size_t bytes);
// Bytes [offset, offset + bytes) of the file with `fd` will be read soon: the kernel reads them
// into the page cache (nothing is mapped: the resident set does not grow). It reads at most its
// read-ahead window per hint (read_ahead_kb, or the device's largest request) and silently
// drops the rest, so this gives one hint per MiB: one hint for a batch of hundreds of MB read
// 8 MB of it, and a save beyond the budget then waited on a fault per window (85 MB/s from a
// disk that reads 1.4 GB/s). The kernel submits the reads as it goes, waiting when the
// device's queue is full: call it from a thread that has nothing else to do.
void readFileAhead(int fd, std::uint64_t offset, std::uint64_t bytes);
// Gives the pages of [memory, memory + bytes) back (file-backed: their data stays in the
// file and the page cache).
void dropResidentPages(void* memory, std::size_t bytes);

inline constexpr std::size_t kSmallPageBytes = 4096;

// The whole pages of `pageBytes` (a power of two) inside [memory, memory + bytes), as the
// addresses [first, last); none when last <= first.
struct WholePages {
    std::uintptr_t first;
    std::uintptr_t last;
};
inline WholePages wholePages(const void* memory, std::size_t bytes, std::size_t pageBytes) {
    const auto begin = reinterpret_cast<std::uintptr_t>(memory);
    return {(begin + pageBytes - 1) & ~(pageBytes - 1), (begin + bytes) & ~(pageBytes - 1)};
}

// madvise(advice) on the whole pages of `pageBytes` (a power of two) inside
// [memory, memory + bytes); nothing when there are none.
inline void adviseWholePages(const void* memory, std::size_t bytes, std::size_t pageBytes,
                             int advice) {
    const WholePages pages = wholePages(memory, bytes, pageBytes);
    if (pages.last > pages.first) {
        madvise(reinterpret_cast<void*>(pages.first), pages.last - pages.first, advice);
    }
}

// Advises huge pages for the whole 2 MiB pages inside [memory, memory + bytes): for a large
// buffer allocated elsewhere (a reserved std::vector) and not touched yet, so its first touch
// takes a fault per 2 MiB instead of per 4 KiB. Advice only: a refusal changes nothing. Where
// huge pages do not pay off it advises against them (a kernel set to "always" would use them).
inline void adviseHugePages(const void* memory, std::size_t bytes) {
    adviseWholePages(memory, bytes, kHugePageBytes,
                     hugePagesPayOff() ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
}

// Gives back the whole small pages inside [memory, memory + bytes) of an anonymous buffer whose
// contents are no longer needed: they read as zero afterwards, and cost memory again only if
// touched. For a large buffer consumed piece by piece (the sorter's arrival-order input).
inline void releasePages(const void* memory, std::size_t bytes) {
    adviseWholePages(memory, bytes, kSmallPageBytes, MADV_DONTNEED);
}

// Faults in, writable, the small pages that hold [memory, memory + bytes) of an anonymous
// buffer, in one call: for a range about to be filled by a bulk copy, which costs a quarter more
// when it faults page by page (bench/page_cost_bench: populated against anonymous). Advice
// only: a kernel without MADV_POPULATE_WRITE (before 5.14) leaves the faults to the copy.
inline void populatePages(const void* memory, std::size_t bytes) {
    if (bytes == 0) {
        return;
    }
    const auto begin = reinterpret_cast<std::uintptr_t>(memory) & ~(kSmallPageBytes - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(memory) + bytes + kSmallPageBytes - 1) &
                     ~(kSmallPageBytes - 1);
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
}

// Writes a byte to each small page wholly inside [memory, memory + bytes) of an anonymous
// buffer not written yet (it reads as zero, so the zero written changes nothing): its faults,
// taken from user space on the calling thread. Where a hypervisor shadows the guest's page
// tables, a page populatePages() faulted in still costs an exit at its first user access; one
// touched here does not (see IncrementalMortonSorter::populateAhead). The pages only partly
// inside are left alone: other threads may be writing the rest of them.
inline void touchWholePages(void* memory, std::size_t bytes) {
    const WholePages pages = wholePages(memory, bytes, kSmallPageBytes);
    for (std::uintptr_t page = pages.first; page < pages.last; page += kSmallPageBytes) {
        *reinterpret_cast<volatile std::byte*>(page) = std::byte{0};
    }
}

// `bytes` rounded up to whole 2 MiB pages, aligned to one and advised as huge where `pages`
// asks for them and they pay off (small pages otherwise); uninitialised, freed with std::free.
// Advice only: a refusal leaves the kernel's default. Throws std::bad_alloc.
inline void* allocateInHugePages(std::size_t bytes, PageSize pages) {
    const std::size_t mapped = hugePageArrayBytes(bytes);
    void* memory = std::aligned_alloc(kHugePageBytes, mapped);
    if (memory == nullptr) {
        throw std::bad_alloc();
    }
    const bool huge = pages == PageSize::Huge && hugePagesPayOff();
    madvise(memory, mapped, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
    return memory;
}

template <typename T> class HugePageArray {
    static_assert(std::is_trivially_copyable_v<T>, "elements are left uninitialised");

public:
    HugePageArray() = default;
    // In a scratch file (see FileBacking).
    HugePageArray(std::size_t size, const FileBacking& backing) : m_size(size) {
        if (size == 0) {
            return;
        }
        m_mappedBytes = hugePageArrayBytes(size * sizeof(T));
        int fd = -1;
        m_data.reset(static_cast<T*>(mapScratchFile(backing.folder, m_mappedBytes, fd)));
        m_data.get_deleter().mappedBytes = m_mappedBytes;
        m_data.get_deleter().fd = fd;
    }
    explicit HugePageArray(std::size_t size, PageSize pages = PageSize::Huge) : m_size(size) {
        if (size == 0) {
            return;
        }
        m_data.reset(static_cast<T*>(allocateInHugePages(size * sizeof(T), pages)));
    }

    std::size_t size() const { return m_size; }
    std::size_t bytesAllocated() const {
        return m_size == 0 ? 0 : hugePageArrayBytes(m_size * sizeof(T));
    }
    T* data() { return m_data.get(); }
    const T* data() const { return m_data.get(); }
    T& operator[](std::size_t i) { return m_data[i]; }
    const T& operator[](std::size_t i) const { return m_data[i]; }
    operator std::span<T>() { return {m_data.get(), m_size}; }
    operator std::span<const T>() const { return {m_data.get(), m_size}; }

    bool fileBacked() const { return m_mappedBytes != 0; }
    // File-backed only: elements [begin, end) will be read soon (readFileAhead; the mapping
    // starts at the file's first byte).
    void willRead(std::size_t begin, std::size_t end) const {
        end = std::min(end, m_size);
        if (m_mappedBytes != 0 && begin < end) {
            readFileAhead(m_data.get_deleter().fd, begin * sizeof(T), (end - begin) * sizeof(T));
        }
    }
    // File-backed only: stores `values` at elements [first, first + values.size()) with a
    // write to the file rather than through the mapping. A store through the mapping faults
    // each page in first, and a page of the reserved file reads as zeros the kernel has to
    // write (measured: 16 % of a 200 M-point build beyond its budget); a whole-page write
    // needs neither.
    void writeAt(std::size_t first, std::span<const T> values) const {
        if (!values.empty()) {
            writeScratchFile(m_data.get_deleter().fd, first * sizeof(T), values.data(),
                             values.size_bytes());
        }
    }
    // File-backed only: the array's pages leave the resident set (any thread; readers and
    // writers may go on: a page they touch next is faulted back in with its data).
    void dropResident() const {
        if (m_mappedBytes != 0) {
            dropResidentPages(m_data.get(), m_mappedBytes);
        }
    }

private:
    struct Free {
        std::size_t mappedBytes = 0; // > 0: a scratch-file mapping
        int fd = -1;                 // its file
        void operator()(T* pointer) const {
            if (mappedBytes != 0) {
                unmapScratchFile(pointer, mappedBytes, fd);
            } else {
                std::free(pointer);
            }
        }
    };
    std::unique_ptr<T[], Free> m_data;
    std::size_t m_size = 0;
    std::size_t m_mappedBytes = 0;
};

} // namespace omicron
