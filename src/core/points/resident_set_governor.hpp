// Keeps a process's resident set near a limit by dropping pages that can come back: the
// file-backed arrays of a sorted cloud larger than the memory budget (points/sorted_cloud.hpp).
//
// The sorter writes such a cloud, the builder scans it, a writer or a front reads it: each
// touches pages that stay resident until someone gives them back. Rather than each of them
// tracking what it touched, a thread looks at the process's resident set (/proc/self/statm,
// one read) every few milliseconds and, above the limit, drops every page of the cloud's
// mappings. Their data stays in the file and the page cache; whatever is touched next is
// faulted back in. Between two looks the resident set grows by at most what the process
// touches in that time (a few tens of MiB at full speed).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

namespace omicron {

class ResidentSetGovernor {
public:
    // Starts the thread; `drop` runs on it whenever the resident set exceeds `limitBytes`.
    ResidentSetGovernor(std::uint64_t limitBytes, std::function<void()> drop);
    ~ResidentSetGovernor(); // stops and joins the thread
    ResidentSetGovernor(const ResidentSetGovernor&) = delete;
    ResidentSetGovernor& operator=(const ResidentSetGovernor&) = delete;

    std::uint64_t limitBytes() const { return m_limit; }
    // One look now, on the calling thread, as the thread does it: for the loops that touch
    // the most pages (a merge filling the cloud, a save reading it), which should not depend
    // on the thread being scheduled in time on a busy machine. Any thread. True when it
    // dropped.
    bool checkNow();
    std::uint64_t drops() const { return m_drops.load(std::memory_order_relaxed); }

private:
    void run();
    enum class Look { Under, NothingToDrop, Dropped };
    Look look();

    std::uint64_t m_limit;
    std::function<void()> m_drop;
    std::atomic<std::uint64_t> m_drops{0};
    // File-backed resident bytes right after the last drop, and the least ever (0: no drop yet).
    std::atomic<std::uint64_t> m_afterDrop{0};
    std::atomic<std::uint64_t> m_leastAfterDrop{0};
    std::mutex m_mutex;
    std::condition_variable m_wake;
    bool m_stop = false;
    std::thread m_thread; // last: started when everything above exists
};

} // namespace omicron
