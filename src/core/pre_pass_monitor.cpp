#include "pre_pass_monitor.hpp"

namespace omicron {

OpenCancelled::OpenCancelled(const std::string& path, std::uint64_t bytesScanned)
    : std::runtime_error(path + ": opening cancelled during the bounds pre-pass (after " +
                         std::to_string(bytesScanned) + " bytes)"),
      m_path(path), m_bytesScanned(bytesScanned) {}

bool PrePassMonitor::report(std::uint64_t offset) {
    m_nextReport = offset + kReportBytes;
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
