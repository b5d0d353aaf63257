// The reading side of a sort larger than memory: points are buffered with their Morton codes
// up to a run's worth (sized from the memory budget), then stably sorted by code and written
// as one run file of point records (points/point_records.hpp) in the scratch folder. Runs are
// cut in input order, so merging them with ties taken in run order (RunMerger) gives exactly
// the stable Morton order an in-memory sort of the whole input gives.
//
// A run leaves out the columns uniform when it is spilled (every point so far holds the first
// point's intensity, or LAS record): its records are smaller, and the merge puts the value
// back (RunMerger's LeftOutColumns).
//
// Two buffers: a full one is sorted and written on a thread of its own while the reading
// thread fills the other. Sorting and writing a run took three quarters of the read phase,
// with the reader waiting (200 M points under a 1 GiB budget: 4.8 of 6.4 s).
#pragma once

#include "points/morton.hpp"
#include "points/point_batch.hpp"
#include "points/point_records.hpp"
#include "sort/scratch_folder.hpp"

#include <atomic>
#include <cstdint>
#include <future>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace omicron {

struct SortedRun {
    std::unique_ptr<ScratchFile> file;
    std::uint64_t points = 0;
    PointRecordLayout layout; // of its records: the attributes' less its left-out columns
};

// The columns every point added so far shares (the sorter's uniform columns).
struct UniformSoFar {
    bool intensity = false;
    bool las = false;
};

class RunSpiller {
public:
    // Bytes a point of a run costs: its record and code in the buffer being filled and in the
    // one being spilled, and the sort's index and scratch. The budget divided by this (less
    // fixed buffers) is a run's size.
    static std::size_t bytesPerBufferedPoint(AttributeSet attributes);

    // A scratch folder under `tempParent` (see ScratchFolder); throws OutputError when that
    // file system has less free space than `totalPoints` records need.
    RunSpiller(const std::string& tempParent, AttributeSet attributes, std::size_t runPoints,
               std::uint64_t totalPoints);

    // Reading thread: buffers `batch` (codes[i] is the code of point i), spilling every full
    // run without the columns `uniform` says every point added so far, `batch` included,
    // shares. Throws what writing the previous run threw (OutputError: a full disk).
    void add(const PointBatch& batch, std::span<const morton::Code> codes,
             UniformSoFar uniform = {});
    // Spills what is buffered, waits for every run to be written and frees the buffers; call
    // once, after the last add().
    void finish();

    // The runs written so far (the one being written is not among them until the next spill
    // or finish()). Reading thread only.
    const std::vector<SortedRun>& runs() const { return m_runs; }
    // How many runs() holds, for any thread (progress).
    std::size_t runsWritten() const { return m_runsWritten.load(std::memory_order_relaxed); }
    AttributeSet attributes() const { return m_buffer.attributes; }
    std::size_t runPoints() const { return m_runPoints; }
    const ScratchFolder& folder() const { return m_folder; }

private:
    // Waits for the run being written (rethrowing its error) and hands the full buffer to a
    // thread that sorts and writes it, without the columns m_uniform says are uniform so far.
    void startSpill();
    // Waits for the run being written, if any, and adds it to m_runs; rethrows its error.
    void collectSpill();
    // The spilling thread: sorts m_spilled by m_spilledCodes and writes it as run `index`.
    SortedRun writeRun(std::size_t index, PointRecordLayout layout);

    ScratchFolder m_folder;
    PointRecordLayout m_layout; // every column
    std::size_t m_runPoints;
    UniformSoFar m_uniform;            // as of the last add()
    PointBatch m_buffer;               // being filled (reading thread)
    std::vector<morton::Code> m_codes; // their codes
    PointBatch m_spilled;              // being sorted and written (the spilling thread)
    std::vector<morton::Code> m_spilledCodes;
    std::size_t m_runsStarted = 0;
    std::vector<SortedRun> m_runs;
    std::atomic<std::size_t> m_runsWritten{0};
    // Last: destroyed first, waiting for a run still being written (the reader threw).
    std::future<SortedRun> m_spilling;
};

} // namespace omicron
