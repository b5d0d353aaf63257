#include "sort/run_spiller.hpp"

#include "io/atomic_file_writer.hpp"
#include "memory_budget.hpp"
#include "sort/radix_sort.hpp"

#include <algorithm>
#include <numeric>
#include <tbb/parallel_for.h>
#include <utility>

namespace omicron {

namespace {

// Records are encoded into blocks of this size before each write.
constexpr std::size_t kWriteBlockBytes = std::size_t{4} << 20;

} // namespace

std::size_t RunSpiller::bytesPerBufferedPoint(AttributeSet attributes) {
    // Record and code in each of the two buffers, then the sort's index, the index's scratch
    // copy and the codes' scratch copy.
    return 2 * (pointBytes(attributes) + sizeof(morton::Code)) + 2 * sizeof(std::uint32_t) +
           sizeof(std::uint64_t);
}

RunSpiller::RunSpiller(const std::string& tempParent, AttributeSet attributes,
                       std::size_t runPoints, std::uint64_t totalPoints)
    : m_folder(tempParent), m_layout(PointRecordLayout::of(attributes)),
      m_runPoints(std::max<std::size_t>(runPoints, 1)) {
    const std::uint64_t needed = totalPoints * m_layout.bytes;
    m_folder.setBytesNeeded(needed);
    const std::uint64_t free = m_folder.freeBytes();
    if (free < needed) {
        throw OutputError(m_folder.parent() + ": the sorted runs of this cloud need " +
                          formatByteSize(needed) + " (" + std::to_string(needed) +
                          " bytes) of scratch space, but only " + formatByteSize(free) +
                          " are free there; free space or choose another folder with "
                          "--temp-dir");
    }
    m_buffer.attributes = attributes;
    m_spilled.attributes = attributes;
    // Reserved, not touched: pages become resident as the runs fill, and never move.
    m_buffer.reserve(m_runPoints);
    m_codes.reserve(m_runPoints);
    m_spilled.reserve(m_runPoints);
    m_spilledCodes.reserve(m_runPoints);
}

void RunSpiller::add(const PointBatch& batch, std::span<const morton::Code> codes,
                     UniformSoFar uniform) {
    m_uniform = uniform;
    for (std::size_t first = 0; first < batch.size();) {
        const std::size_t room = m_runPoints - m_buffer.size();
        const std::size_t take = std::min(room, batch.size() - first);
        m_buffer.appendRange(batch, first, first + take);
        m_codes.insert(m_codes.end(), codes.begin() + first, codes.begin() + first + take);
        first += take;
        if (m_buffer.size() == m_runPoints) {
            startSpill();
        }
    }
}

void RunSpiller::finish() {
    if (!m_buffer.empty()) {
        startSpill();
    }
    collectSpill();
    // The buffers' memory goes back before the merge needs its own.
    for (PointBatch* buffer : {&m_buffer, &m_spilled}) {
        PointBatch released;
        released.attributes = buffer->attributes;
        *buffer = std::move(released);
    }
    m_codes = {};
    m_spilledCodes = {};
}

void RunSpiller::collectSpill() {
    if (m_spilling.valid()) {
        m_runs.push_back(m_spilling.get());
        m_runsWritten.store(m_runs.size(), std::memory_order_relaxed);
    }
}

void RunSpiller::startSpill() {
    const PointRecordLayout layout = m_layout.without(m_uniform.intensity, m_uniform.las);
    collectSpill(); // the other buffer is free again
    std::swap(m_buffer, m_spilled);
    std::swap(m_codes, m_spilledCodes);
    m_buffer.clear();
    m_codes.clear();
    m_spilling = std::async(std::launch::async, [this, index = m_runsStarted++, layout] {
        return writeRun(index, layout);
    });
}

SortedRun RunSpiller::writeRun(std::size_t index, PointRecordLayout layout) {
    const std::size_t n = m_spilled.size();
    // Stable: equal codes keep their input order, which the merge then keeps across runs.
    std::vector<std::uint32_t> order(n), orderScratch(n);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<std::uint64_t> keyScratch(n);
    radixSortByKey(std::span(m_spilledCodes.data(), n), std::span(order.data(), n),
                   std::span(keyScratch.data(), n), std::span(orderScratch.data(), n));
    keyScratch = {};
    orderScratch = {};

    SortedRun run;
    run.file = std::make_unique<ScratchFile>(m_folder, "run-" + std::to_string(index));
    run.points = n;
    run.layout = layout;
    const std::size_t recordsPerBlock = std::max<std::size_t>(1, kWriteBlockBytes / layout.bytes);
    std::vector<std::uint8_t> block;
    for (std::size_t first = 0; first < n; first += recordsPerBlock) {
        const std::size_t count = std::min(recordsPerBlock, n - first);
        block.resize(count * layout.bytes);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 16384),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t i = range.begin(); i < range.end(); ++i) {
                                  encodePointRecord(layout, m_spilled, order[first + i],
                                                    block.data() + i * layout.bytes);
                              }
                          });
        run.file->write(block.data(), block.size());
    }
    return run;
}

} // namespace omicron
