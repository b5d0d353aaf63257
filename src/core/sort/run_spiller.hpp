// The reading side of a sort larger than memory: points are buffered with their Morton codes
// up to a run's worth (sized from the memory budget), then stably sorted by code and written
// as one run file of point records (points/point_records.hpp) in the scratch folder. Runs are
// cut in input order, so merging them with ties taken in run order (RunMerger) gives exactly
// the stable Morton order an in-memory sort of the whole input gives.
#pragma once

#include "points/morton.hpp"
#include "points/point_batch.hpp"
#include "points/point_records.hpp"
#include "sort/scratch_folder.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace omicron {

struct SortedRun {
    std::unique_ptr<ScratchFile> file;
    std::uint64_t points = 0;
};

class RunSpiller {
public:
    // Bytes a buffered point costs: its record in the batch, its code, the sort's key, index
    // and scratch. The budget divided by this (less fixed buffers) is a run's size.
    static std::size_t bytesPerBufferedPoint(AttributeSet attributes);

    // A scratch folder under `tempParent` (see ScratchFolder); throws OutputError when that
    // file system has less free space than `totalPoints` records need.
    RunSpiller(const std::string& tempParent, AttributeSet attributes, std::size_t runPoints,
               std::uint64_t totalPoints);

    // Reading thread: buffers `batch` (codes[i] is the code of point i), spilling every full run.
    void add(const PointBatch& batch, std::span<const morton::Code> codes);
    // Spills what is buffered and frees the buffers; call once, after the last add().
    void finish();

    const std::vector<SortedRun>& runs() const { return m_runs; }
    AttributeSet attributes() const { return m_buffer.attributes; }
    std::size_t runPoints() const { return m_runPoints; }
    const ScratchFolder& folder() const { return m_folder; }

private:
    void spill();

    ScratchFolder m_folder;
    PointRecordLayout m_layout;
    std::size_t m_runPoints;
    PointBatch m_buffer;
    std::vector<morton::Code> m_codes;
    std::vector<SortedRun> m_runs;
};

} // namespace omicron
