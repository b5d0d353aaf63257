#include "points/resident_set_governor.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <unistd.h>

namespace omicron {

namespace {

// How often the resident set is looked at, and how long to wait while what is over the limit is
// hardly file pages: dropping them then would only make the cloud's readers fault for nothing.
constexpr auto kInterval = std::chrono::milliseconds(2);
constexpr auto kBackOff = std::chrono::milliseconds(250);
// File-backed resident bytes below which a drop is not worth it (the program's own code and
// libraries count there too).
constexpr std::uint64_t kMinDroppable = std::uint64_t{64} << 20;

} // namespace

ResidentSetGovernor::ResidentSetGovernor(std::uint64_t limitBytes, std::function<void()> drop)
    : m_limit(limitBytes), m_drop(std::move(drop)), m_thread([this] { run(); }) {}

ResidentSetGovernor::~ResidentSetGovernor() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
    }
    m_wake.notify_all();
    m_thread.join();
}

namespace {

// Resident and file-backed resident bytes from /proc/self/statm (zeros where unreadable).
std::pair<std::uint64_t, std::uint64_t> readStatm() {
    std::FILE* file = std::fopen("/proc/self/statm", "r");
    if (file == nullptr) {
        return {0, 0};
    }
    unsigned long long pages = 0, resident = 0, shared = 0;
    const int read = std::fscanf(file, "%llu %llu %llu", &pages, &resident, &shared);
    std::fclose(file);
    const auto page = static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
    return read == 3 ? std::pair{resident * page, shared * page} : std::pair{0ull, 0ull};
}

} // namespace

std::uint64_t ResidentSetGovernor::residentBytes() { return readStatm().first; }

ResidentSetGovernor::Look ResidentSetGovernor::look() {
    const auto [resident, fileBacked] = readStatm();
    if (resident <= m_limit) {
        return Look::Under;
    }
    if (fileBacked < std::min<std::uint64_t>(m_limit / 8, kMinDroppable)) {
        return Look::NothingToDrop; // over the limit, but hardly by file pages
    }
    m_drop(); // two threads dropping at once is harmless: the pages are just unmapped
    m_drops.fetch_add(1, std::memory_order_relaxed);
    return Look::Dropped;
}

bool ResidentSetGovernor::checkNow() { return look() == Look::Dropped; }

void ResidentSetGovernor::run() {
    std::unique_lock lock(m_mutex);
    auto wait = kInterval;
    while (!m_wake.wait_for(lock, wait, [&] { return m_stop; })) {
        lock.unlock();
        const Look result = look();
        lock.lock();
        wait = result == Look::NothingToDrop ? kBackOff : kInterval;
    }
}

} // namespace omicron
