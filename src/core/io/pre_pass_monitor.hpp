// The bounds pre-pass's link to whoever opens the file: progress once per block of input and
// the cancel check, so that a front end can show "scanning bounds" and stop a long scan of a
// large PLY or XYZ file (a scan reads the whole file once before any point is delivered).
#pragma once

#include "io/point_reader.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace omicron {

class PrePassMonitor {
public:
    // Reports (and checks the cancel flag) whenever the scan has advanced this many bytes:
    // the size of the readers' blocks, so a binary scan reports once per block.
    static constexpr std::uint64_t kReportBytes = std::uint64_t{1} << 20;

    // `estimatedPoints` (records, or lines of text) sets the stride of the point sample.
    PrePassMonitor(const OpenOptions& options, std::string path, std::uint64_t fileBytes,
                   std::uint64_t estimatedPoints)
        : m_options(options), m_path(std::move(path)), m_fileBytes(fileBytes),
          m_sampleStride(std::max<std::uint64_t>(1, estimatedPoints / kPrePassSamplePoints)) {}

    // The point sample for OpenOptions::onPrePassPoints: record `index` (counting from 0) is
    // sampled when this says so; its finite source position then goes to offer().
    bool samples(std::uint64_t index) const {
        return m_options.onPrePassPoints && index % m_sampleStride == 0;
    }
    // Whether anyone takes the sample at all.
    bool sampling() const { return static_cast<bool>(m_options.onPrePassPoints); }
    std::uint64_t sampleStride() const { return m_sampleStride; }
    void offer(const glm::dvec3& source) { m_sampled.push_back(source); }

    // The scan has read the file up to byte `offset`. Cheap between reports (one compare),
    // so text scans call it per line. False once cancelled: a block visitor returns it to stop
    // the scan, which then ends with finish().
    bool reached(std::uint64_t offset) { return offset < m_nextReport || report(offset); }
    // The same, for a scan that can stop where it stands: throws OpenCancelled when cancelled.
    void advance(std::uint64_t offset) {
        if (!reached(offset)) {
            throwCancelled();
        }
    }
    // advance(), reporting now however few bytes were scanned since the last report: the end
    // of a text scan's first block, so that the view has its first preview points at once.
    void reportNow(std::uint64_t offset) {
        if (!report(offset)) {
            throwCancelled();
        }
    }
    // The scan is over: throws OpenCancelled when it was stopped, else a last report at the
    // file's size.
    void finish() {
        if (m_cancelled) {
            throwCancelled();
        }
        report(m_fileBytes);
    }

private:
    bool report(std::uint64_t offset);
    [[noreturn]] void throwCancelled() const;

    const OpenOptions& m_options;
    std::string m_path;
    std::uint64_t m_fileBytes;
    std::uint64_t m_nextReport = 0; // the first call reports: a scan starts visibly
    bool m_cancelled = false;
    std::uint64_t m_bytesScanned = 0;
    std::uint64_t m_sampleStride;
    std::vector<glm::dvec3> m_sampled; // since the last report
};

} // namespace omicron
