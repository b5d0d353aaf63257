// A progress line on stderr: rewritten in place on a terminal, at most 5 times a second; a
// line every 10 % when stderr is a file or pipe (so logs stay readable).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace omicron::cli {

class ProgressLine {
public:
    ProgressLine();
    void update(const std::string& stage, std::uint64_t done, std::uint64_t total);
    void finish(); // ends the line

private:
    bool m_terminal;
    bool m_open = false;
    std::string m_stage;
    int m_lastTenth = -1;
    std::chrono::steady_clock::time_point m_lastPrint{};
};

} // namespace omicron::cli
