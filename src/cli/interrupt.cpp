#include "interrupt.hpp"

#include <csignal>
#include <mutex>

namespace omicron::cli {

namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void onInterrupt(int) {
    g_interrupted.store(true, std::memory_order_relaxed);
}

} // namespace

const std::atomic<bool>& watchInterrupts() {
    static std::once_flag installed;
    std::call_once(installed, [] {
        struct sigaction action = {};
        action.sa_handler = onInterrupt;
        sigemptyset(&action.sa_mask);
        action.sa_flags = SA_RESETHAND; // the second signal takes the default action
        sigaction(SIGINT, &action, nullptr);
        sigaction(SIGTERM, &action, nullptr);
    });
    return g_interrupted;
}

void throwIfInterrupted() {
    if (g_interrupted.load(std::memory_order_relaxed)) {
        throw Interrupted();
    }
}

} // namespace omicron::cli
