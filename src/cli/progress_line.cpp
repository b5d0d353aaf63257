#include "progress_line.hpp"

#include <cstdio>
#include <unistd.h>

namespace omicron::cli {

ProgressLine::ProgressLine() : m_terminal(::isatty(STDERR_FILENO) == 1) {}

void ProgressLine::update(const std::string& stage, std::uint64_t done, std::uint64_t total) {
    const double percent = total == 0 ? 100.0 : 100.0 * static_cast<double>(done) / total;
    const auto now = std::chrono::steady_clock::now();
    if (m_terminal) {
        if (stage == m_stage && done != total &&
            now - m_lastPrint < std::chrono::milliseconds(200)) {
            return;
        }
        std::fprintf(stderr, "\r%s: %llu / %llu points (%.0f %%)   ", stage.c_str(),
                     static_cast<unsigned long long>(done), static_cast<unsigned long long>(total),
                     percent);
        m_open = true;
    } else {
        const int tenth = static_cast<int>(percent / 10.0);
        if (stage == m_stage && tenth == m_lastTenth) {
            return;
        }
        m_lastTenth = tenth;
        std::fprintf(stderr, "%s: %llu / %llu points (%.0f %%)\n", stage.c_str(),
                     static_cast<unsigned long long>(done), static_cast<unsigned long long>(total),
                     percent);
    }
    m_stage = stage;
    m_lastPrint = now;
    std::fflush(stderr);
}

void ProgressLine::finish() {
    if (m_open) {
        std::fputc('\n', stderr);
        m_open = false;
    }
}

} // namespace omicron::cli
