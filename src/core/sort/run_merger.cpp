#include "sort/run_merger.hpp"

#include <algorithm>
#include <cstring>

namespace omicron {

RunMerger::RunMerger(const std::vector<SortedRun>& runs, std::size_t bufferBytes,
                     const LeftOutColumns& leftOut)
    : m_leftOut(leftOut) {
    const std::size_t perRun = bufferBytes / std::max<std::size_t>(runs.size(), 1);
    m_cursors.resize(runs.size());
    for (std::size_t r = 0; r < runs.size(); ++r) {
        m_cursors[r].file = runs[r].file.get();
        m_cursors[r].layout = runs[r].layout;
        m_cursors[r].recordsPerBuffer = std::max<std::size_t>(1, perRun / runs[r].layout.bytes);
        m_cursors[r].points = runs[r].points;
        m_pointsLeft += runs[r].points;
        if (refill(m_cursors[r])) {
            m_heap.push_back(static_cast<std::uint32_t>(r));
        }
    }
    for (std::size_t slot = m_heap.size() / 2; slot-- > 0;) {
        siftDown(slot);
    }
}

bool RunMerger::refill(Cursor& cursor) {
    if (cursor.nextToLoad == cursor.points) {
        return false;
    }
    const std::size_t recordBytes = cursor.layout.bytes;
    const std::size_t count = static_cast<std::size_t>(
        std::min<std::uint64_t>(cursor.recordsPerBuffer, cursor.points - cursor.nextToLoad));
    cursor.records.resize(count * recordBytes);
    cursor.file->read(cursor.nextToLoad * recordBytes, cursor.records.data(),
                      cursor.records.size());
    // The code of a stored float position is bit for bit the one the run was sorted by.
    cursor.codes.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        float xyz[3];
        std::memcpy(xyz, cursor.records.data() + i * recordBytes, sizeof xyz);
        cursor.codes[i] = morton::encodeUnit(xyz[0], xyz[1], xyz[2]);
    }
    cursor.nextToLoad += count;
    cursor.at = 0;
    cursor.buffered = count;
    if (cursor.nextToLoad < cursor.points) {
        if (m_readAhead.valid()) {
            m_readAhead.get(); // long done: another run's buffer was merged meanwhile
        }
        const ScratchFile* file = cursor.file;
        const std::uint64_t offset = cursor.nextToLoad * recordBytes;
        const std::uint64_t bytes = std::uint64_t{cursor.recordsPerBuffer} * recordBytes;
        m_readAhead = std::async(std::launch::async,
                                 [file, offset, bytes] { file->willRead(offset, bytes); });
    }
    return true;
}

bool RunMerger::lessThan(std::uint32_t a, std::uint32_t b) const {
    const morton::Code codeA = m_cursors[a].codes[m_cursors[a].at];
    const morton::Code codeB = m_cursors[b].codes[m_cursors[b].at];
    return codeA < codeB || (codeA == codeB && a < b);
}

void RunMerger::siftDown(std::size_t slot) {
    const std::size_t size = m_heap.size();
    for (;;) {
        const std::size_t left = 2 * slot + 1;
        if (left >= size) {
            return;
        }
        std::size_t smallest = left;
        if (left + 1 < size && lessThan(m_heap[left + 1], m_heap[left])) {
            smallest = left + 1;
        }
        if (!lessThan(m_heap[smallest], m_heap[slot])) {
            return;
        }
        std::swap(m_heap[smallest], m_heap[slot]);
        slot = smallest;
    }
}

std::size_t RunMerger::next(PointBatch& out, std::size_t maxPoints) {
    std::size_t emitted = 0;
    while (emitted < maxPoints && !m_heap.empty()) {
        Cursor& top = m_cursors[m_heap.front()];
        decodePointRecord(top.layout, top.records.data() + top.at * top.layout.bytes, out,
                          m_leftOut);
        ++emitted;
        if (++top.at == top.buffered && !refill(top)) {
            m_heap.front() = m_heap.back();
            m_heap.pop_back();
        }
        if (!m_heap.empty()) {
            siftDown(0);
        }
    }
    m_pointsLeft -= emitted;
    return emitted;
}

} // namespace omicron
