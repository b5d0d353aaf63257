#include "points/resident_set_governor.hpp"

#include "memory_budget.hpp"

#include <algorithm>
#include <chrono>

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


ResidentSetGovernor::Look ResidentSetGovernor::look() {
    const ResidentSet resident = processResidentSet();
    if (resident.bytes <= m_limit) {
        return Look::Under;
    }
    const std::uint64_t worthDropping = std::min<std::uint64_t>(m_limit / 8, kMinDroppable);
    if (resident.fileBackedBytes < worthDropping) {
        return Look::NothingToDrop; // over the limit, but hardly by file pages
    }
    // What a drop leaves is the program's own file pages (its code, its libraries), which
    // under a small budget are alone over an eighth of it: drop again only once the cloud's
    // pages have grown by that much since. Each drop unmaps pages on every core (a TLB
    // shootdown), and a save of many small batches looked before each one: with a drop every
    // time, 28k batches over lion.ply under 4 MiB spent most of the save in madvise.
    // What a drop left is measured again at each drop, since other threads may fault pages
    // back in meanwhile; it counts up to an eighth above the least ever left, so such a
    // measure cannot let the cloud's pages grow by more than twice that (the least ever left
    // alone kept the save of 1-point batches at 20 s, not 10).
    const std::uint64_t left =
        std::min(m_afterDrop.load(std::memory_order_relaxed),
                 m_leastAfterDrop.load(std::memory_order_relaxed) + worthDropping);
    if (resident.fileBackedBytes < left + worthDropping) {
        return Look::Under;
    }
    m_drop(); // two threads dropping at once is harmless: the pages are just unmapped
    m_drops.fetch_add(1, std::memory_order_relaxed);
    const std::uint64_t after = processResidentSet().fileBackedBytes;
    m_afterDrop.store(after, std::memory_order_relaxed);
    std::uint64_t least = m_leastAfterDrop.load(std::memory_order_relaxed);
    while ((least == 0 || after < least) &&
           !m_leastAfterDrop.compare_exchange_weak(least, after, std::memory_order_relaxed)) {
    }
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
