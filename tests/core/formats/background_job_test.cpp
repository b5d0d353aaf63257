// The `.omh` sweep's writer and read-ahead thread: jobs run one at a time, in order, on one
// thread kept for all of them; at most `depth` are queued or running; what a job throws comes
// back at the next start() or wait(), and the jobs queued behind it are dropped; the
// destructor waits for the jobs queued.
#include "formats/background_job.hpp"

#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace omicron {
namespace {

TEST(BackgroundJob, RunsJobsInOrderOneAtATimeOnOneThread) {
    std::vector<int> order;
    std::set<std::thread::id> threads;
    std::atomic<int> running{0};
    bool overlapped = false;
    {
        BackgroundJob job;
        for (int i = 0; i < 200; ++i) {
            job.start([&, i] {
                overlapped = overlapped || running.fetch_add(1) != 0;
                if (i % 50 == 0) { // a slow one: the next start() must wait for it
                    std::this_thread::sleep_for(std::chrono::milliseconds(5));
                }
                order.push_back(i);
                threads.insert(std::this_thread::get_id());
                running.fetch_sub(1);
            });
        }
        job.wait();
        EXPECT_EQ(order.size(), 200u);
    }
    for (int i = 0; i < 200; ++i) {
        ASSERT_EQ(order[static_cast<std::size_t>(i)], i);
    }
    EXPECT_FALSE(overlapped);
    ASSERT_EQ(threads.size(), 1u);
    EXPECT_NE(*threads.begin(), std::this_thread::get_id());
}

TEST(BackgroundJob, AJobsErrorComesBackAtTheNextStartOrWait) {
    BackgroundJob job;
    job.start([] { throw std::runtime_error("disk full"); });
    bool ranNext = false;
    EXPECT_THROW(job.start([&] { ranNext = true; }), std::runtime_error);
    EXPECT_FALSE(ranNext) << "a job started after a failed one";
    job.start([&] { ranNext = true; }); // the error was reported once
    job.wait();
    EXPECT_TRUE(ranNext);
    job.start([] { throw std::runtime_error("read error"); });
    EXPECT_THROW(job.wait(), std::runtime_error);
    EXPECT_NO_THROW(job.wait());
}

TEST(BackgroundJob, TheDestructorWaitsForTheJobInFlight) {
    std::atomic<bool> done{false};
    {
        BackgroundJob job;
        job.start([&] {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            done = true;
        });
    }
    EXPECT_TRUE(done.load());
}

// Sets `flag` after `delay` on a thread of its own (joined by the destructor), so that a test
// whose job waits for it ends even when start() wrongly waits for that job.
class DelayedRelease {
public:
    DelayedRelease(std::atomic<bool>& flag, std::chrono::milliseconds delay)
        : m_thread([&flag, delay] {
              std::this_thread::sleep_for(delay);
              flag = true;
          }) {}
    ~DelayedRelease() { m_thread.join(); }

private:
    std::thread m_thread;
};

void waitFor(const std::atomic<bool>& flag) {
    while (!flag.load()) {
        std::this_thread::yield();
    }
}

TEST(BackgroundJob, ADeeperQueueLetsTheCallerRunAheadByThatManyJobs) {
    BackgroundJob job(2);
    std::atomic<bool> release{false};
    std::atomic<int> done{0};
    const DelayedRelease releaser(release, std::chrono::milliseconds(500));
    job.start([&] {
        waitFor(release);
        done.fetch_add(1);
    });
    job.start([&] { done.fetch_add(1); }); // queued behind the running one: returns at once
    EXPECT_EQ(done.load(), 0) << "start() waited for the job before";
    std::atomic<bool> thirdQueued{false};
    std::thread caller([&] {
        job.start([&] { done.fetch_add(1); }); // waits: two are queued or running
        thirdQueued = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_FALSE(thirdQueued.load() && !release.load()) << "a third job was queued beside two";
    caller.join();
    job.wait();
    EXPECT_EQ(done.load(), 3);
}

TEST(BackgroundJob, JobsQueuedBehindAFailedOneAreDropped) {
    BackgroundJob job(3);
    std::atomic<bool> release{false};
    std::atomic<bool> ranAfter{false};
    {
        const DelayedRelease releaser(release, std::chrono::milliseconds(50));
        job.start([&] {
            waitFor(release);
            throw std::runtime_error("disk full");
        });
        job.start([&] { ranAfter = true; });
        EXPECT_THROW(job.wait(), std::runtime_error);
    }
    EXPECT_FALSE(ranAfter.load()) << "a write ran after the one before it failed";
    job.start([&] { ranAfter = true; }); // the error was reported once
    job.wait();
    EXPECT_TRUE(ranAfter.load());
}

TEST(BackgroundJob, WaitingWithoutAJobReturnsAtOnce) {
    BackgroundJob job;
    EXPECT_NO_THROW(job.wait());
}

} // namespace
} // namespace omicron
