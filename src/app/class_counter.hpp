// ClassCounter: the points per ASPRS class of the cloud a view shows, counted on a thread of
// its own so the GUI thread never walks a big cloud. It follows a growing cloud: the sorted
// prefix is counted as it is published, a chunk at a time, and snapshot() may be read at any
// moment (the Classes dock polls it). A rebuild over the same sorted points keeps the counts.
#pragma once

#include "points/asprs_classes.hpp"

#include <array>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stop_token>
#include <thread>

namespace omicron {

class Hierarchy;
class SortedCloud;

class ClassCounter {
public:
    // What has been counted so far.
    struct Snapshot {
        std::array<std::uint64_t, kLasClassCount> counts{}; // points per class
        std::uint64_t counted = 0;                          // points counted (of `total`)
        std::uint64_t total = 0;                            // points of the cloud
        bool hasClasses = false; // the cloud has a LAS column (else every point is class 0)
        bool complete = false;   // every point counted
        // A hierarchy paged in on demand: its points are read only as the view asks for them,
        // so they are not counted (counts stay zero).
        bool notCounted = false;
    };

    ClassCounter() = default;
    ~ClassCounter();
    ClassCounter(const ClassCounter&) = delete;
    ClassCounter& operator=(const ClassCounter&) = delete;

    // Counts the cloud of `hierarchy` (nullptr: none). The same cloud as before (a rebuild)
    // goes on where it was; another one starts from zero. Stopping the previous count waits
    // for at most one chunk (kChunkPoints points).
    void setHierarchy(std::shared_ptr<const Hierarchy> hierarchy);
    Snapshot snapshot() const;

    static constexpr std::size_t kChunkPoints = std::size_t{1} << 18;

private:
    void run(std::stop_token stop, std::shared_ptr<const Hierarchy> hierarchy);
    void countPrefix(std::stop_token stop, const SortedCloud& cloud);
    void countLeaves(std::stop_token stop, const Hierarchy& hierarchy);
    void publish(const std::array<std::uint64_t, kLasClassCount>& counts, std::uint64_t counted,
                 bool complete);

    mutable std::mutex m_mutex;
    std::condition_variable_any m_wake; // the count's pause between polls of a growing cloud
    Snapshot m_snapshot;
    // The cloud being counted, for its identity only (weak: a freed cloud's address may be
    // reused by the next one).
    std::weak_ptr<const SortedCloud> m_cloud;
    std::jthread m_thread; // last: stopped and joined before the rest goes
};

} // namespace omicron
