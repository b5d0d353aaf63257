// Saves a finished hierarchy as a .omh file (layout in omh_format.hpp, docs/FORMATS.md),
// atomically: the target is either the complete new file or left as it was.
#pragma once

#include "build/build_options.hpp"
#include "build/build_statistics.hpp"
#include "build/hierarchy.hpp"
#include "formats/omh_column_sink.hpp"
#include "formats/omh_format.hpp"
#include "io/atomic_file_writer.hpp"

#include <functional>
#include <string>

namespace omicron {

struct OmhWriteOptions {
    // Called once for each level after its point records were handed to the file: the top
    // levels from level 0 and then the swept ones, or, over a cloud in a scratch file, the
    // swept levels first. For the test that kills a save half-way (omicron-cli build --save).
    std::function<void(int level)> afterLevel;
    // Points held by a batch of the one-pass sweep that writes the deep levels (0: the
    // default, 1 Mi; for a cloud in a scratch file at most an eighth of the budget's worth, or a
    // 32nd of it when that is more, and bigger where the top levels' copy needs it). The bytes
    // written do not depend on it; tests vary it.
    std::uint64_t sweepBatchPoints = 0;
    // Over a cloud in a scratch file, copy the top levels' points out while the sweep reads
    // the file and write them afterwards (omh_top_levels.hpp) rather than read them in place.
    // The bytes written do not depend on it; tests turn it off.
    bool gatherTopLevels = true;
    // The format version written: omh::kVersion; 3 (every level as records, for readers
    // older than version 4); or 2 (every record with its splat attributes, for readers older
    // than version 3).
    std::uint32_t formatVersion = omh::kVersion;
    // Version 4: the deepest level's columns, already in the file where a build streamed them
    // (omh_column_stream.hpp); used when they are what the level holds, else written over.
    const OmhStreamedColumns* streamedColumns = nullptr;
};

// What a save did beyond its bytes.
struct OmhSaveReport {
    // Bytes of the deepest level's columns taken as OmhWriteOptions::streamedColumns wrote
    // them (0: none given, or written again because they were not what the level holds).
    std::uint64_t streamedBytesUsed = 0;
};

// The header fields a build determines: its parameters and counts.
omh::BuildInfo omhBuildInfo(const BuildOptions& options, const BuildStatistics& statistics);

// Writes every published node of the complete `hierarchy` (built, or loaded from a .omh file)
// with the points each holds: position, the cloud's normal/colour/intensity, the splat radius
// and estimated normal. Loading the file and saving it again gives the same bytes. Throws
// OutputError naming the file (an incomplete hierarchy, build info that disagrees with it,
// I/O errors such as a full disk); the temporary file is removed and the target untouched.
// A hierarchy whose points are paged in on demand (Hierarchy::residency()) is saved as a copy
// of the .omh it reads them from (the same bytes, as above; `build` is its header's and
// afterLevel is not called); an unreadable source is an InputError naming it.
OmhSaveReport writeOmh(const std::string& path, const Hierarchy& hierarchy,
                       const omh::BuildInfo& build, const OmhWriteOptions& options = {});
// The same into `file`, opened before the hierarchy was built (a target that cannot be written
// fails before any work), which it commits.
OmhSaveReport writeOmh(AtomicFileWriter& file, const Hierarchy& hierarchy,
                       const omh::BuildInfo& build, const OmhWriteOptions& options = {});

} // namespace omicron
