#include "io/pre_pass_monitor.hpp"

namespace omicron {

bool PrePassMonitor::report(std::uint64_t offset) {
    m_nextReport = offset + kReportBytes;
    // Points first: a progress observer then sees every sample up to this offset.
    if (m_options.onPrePassPoints && !m_sampled.empty()) {
        m_options.onPrePassPoints(m_sampled);
        m_sampled.clear();
    }
    if (m_options.onPrePassProgress) {
        m_options.onPrePassProgress(offset, m_fileBytes);
    }
    // Checked after the report, so a callback that cancels stops the scan at once.
    if (m_options.cancel != nullptr && m_options.cancel->load(std::memory_order_relaxed)) {
        m_cancelled = true;
        m_bytesScanned = offset;
    }
    return !m_cancelled;
}

void PrePassMonitor::throwCancelled() const {
    throw OpenCancelled(m_path, m_bytesScanned);
}

} // namespace omicron
