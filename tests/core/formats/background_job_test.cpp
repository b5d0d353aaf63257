// The `.omh` sweep's writer and read-ahead thread: jobs run one at a time, in order, on one
// thread kept for all of them; what a job throws comes back at the next start() or wait(); the
// destructor waits for the job in flight.
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

TEST(BackgroundJob, WaitingWithoutAJobReturnsAtOnce) {
    BackgroundJob job;
    EXPECT_NO_THROW(job.wait());
}

} // namespace
} // namespace omicron
