#include "interrupt.hpp"

#include <chrono>
#include <condition_variable>
#include <csignal>
#include <mutex>
#include <thread>

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

PipelineResult runInterruptibly(BuildPipeline& pipeline, const std::string& path,
                                const PipelineOptions& options) {
    const std::atomic<bool>& interrupted = watchInterrupts();
    // The pipeline has its own cancel flag; a watcher hands the signal over. A signal handler
    // cannot notify a condition variable, so the flag is polled; the end of the run wakes the
    // watcher at once (a sleeping watcher held `build --save` up to 20 ms between the
    // hierarchy's completion and the save, with both cores idle).
    std::jthread watcher([&](std::stop_token stop) {
        std::mutex mutex;
        std::condition_variable_any wake;
        std::unique_lock lock(mutex);
        while (!stop.stop_requested()) {
            if (wake.wait_for(lock, stop, std::chrono::milliseconds(20),
                              [&] { return interrupted.load(std::memory_order_relaxed); })) {
                pipeline.cancel();
                return;
            }
        }
    });
    PipelineResult result = pipeline.run(path, options);
    watcher.request_stop();
    watcher.join();
    throwIfInterrupted();
    return result;
}

} // namespace omicron::cli
