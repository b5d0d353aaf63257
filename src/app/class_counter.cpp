#include "class_counter.hpp"

#include "build/hierarchy.hpp"
#include "points/las_fields.hpp"

#include <chrono>

namespace omicron {

namespace {

// How often a count that has caught up with the published prefix looks again.
constexpr auto kPollInterval = std::chrono::milliseconds(50);

} // namespace

ClassCounter::~ClassCounter() {
    m_thread = {}; // request stop and join before the members it writes go
}

void ClassCounter::setHierarchy(std::shared_ptr<const Hierarchy> hierarchy) {
    const std::shared_ptr<const SortedCloud> cloud = hierarchy ? hierarchy->sharedCloud() : nullptr;
    if (cloud != nullptr && cloud == m_cloud.lock()) {
        return; // a rebuild over the same sorted points: the count goes on
    }
    m_thread = {}; // stops (the count checks between chunks) and joins the previous count
    m_cloud = cloud;
    {
        const std::lock_guard lock(m_mutex);
        m_snapshot = Snapshot{};
        if (cloud != nullptr) {
            m_snapshot.total = cloud->capacity();
            m_snapshot.hasClasses = cloud->attributes().has(Attribute::Las);
            m_snapshot.notCounted = cloud->pagedOnDemand();
        }
    }
    if (cloud != nullptr && !cloud->pagedOnDemand()) {
        m_thread = std::jthread([this, hierarchy = std::move(hierarchy)](std::stop_token stop) {
            run(stop, hierarchy);
        });
    }
}

ClassCounter::Snapshot ClassCounter::snapshot() const {
    const std::lock_guard lock(m_mutex);
    return m_snapshot;
}

void ClassCounter::publish(const std::array<std::uint64_t, kLasClassCount>& counts,
                           std::uint64_t counted, bool complete) {
    const std::lock_guard lock(m_mutex);
    m_snapshot.counts = counts;
    m_snapshot.counted = counted;
    m_snapshot.complete = complete;
}

void ClassCounter::run(std::stop_token stop, std::shared_ptr<const Hierarchy> hierarchy) {
    const SortedCloud& cloud = hierarchy->cloud();
    if (cloud.order() == CloudOrder::Morton) {
        countPrefix(stop, cloud);
    } else {
        countLeaves(stop, *hierarchy);
    }
}

// A sorted cloud holds each input point once, published as a growing prefix.
void ClassCounter::countPrefix(std::stop_token stop, const SortedCloud& cloud) {
    std::array<std::uint64_t, kLasClassCount> counts{};
    std::size_t counted = 0;
    while (!stop.stop_requested()) {
        const bool complete = cloud.complete(); // before sortedEnd: then the end is final
        const std::size_t published = cloud.sortedEnd();
        if (counted < published) {
            const std::size_t end = std::min(published, counted + kChunkPoints);
            // Read once a range is published: a uniform column is declared before that.
            const ColumnView<std::uint8_t> las = cloud.lasColumn();
            if (las.empty()) {
                counts[0] += end - counted; // no LAS column: every point is class 0
            } else if (las.stride == 0) {
                counts[las.data[0]] += end - counted; // uniform: one record for every point
            } else {
                for (std::size_t i = counted; i < end; ++i) {
                    ++counts[las[i]]; // the classification is the record's byte 0
                }
            }
            counted = end;
            publish(counts, counted, complete && counted == published);
            continue;
        }
        if (complete) {
            publish(counts, counted, true);
            return;
        }
        std::unique_lock lock(m_mutex);
        m_wake.wait_for(lock, stop, kPollInterval, [] { return false; });
    }
}

// A loaded .omh cloud is in node order, parents' samples included: its leaves hold every input
// point once. The reader publishes level after level; the leaves are counted once it is done.
void ClassCounter::countLeaves(std::stop_token stop, const Hierarchy& hierarchy) {
    const SortedCloud& cloud = hierarchy.cloud();
    while (!stop.stop_requested() && !(cloud.complete() && hierarchy.publishedCut().complete)) {
        std::unique_lock lock(m_mutex);
        m_wake.wait_for(lock, stop, kPollInterval, [] { return false; });
    }
    const AttributeSet attributes = cloud.attributes();
    const std::size_t stride = attributes.lasBytes();
    std::array<std::uint64_t, kLasClassCount> counts{};
    std::uint64_t counted = 0;
    for (int level = 0; level <= hierarchy.maxLevel() && !stop.stop_requested(); ++level) {
        const std::size_t nodes = hierarchy.nodeCount(level);
        for (std::size_t n = 0; n < nodes && !stop.stop_requested(); ++n) {
            const OctreeNode& node = hierarchy.node(level, n);
            if (!node.isLeaf()) {
                continue;
            }
            for (std::uint32_t i = 0; i < node.pointCount; ++i) {
                ++counts[stride == 0 ? 0 : *cloud.lasRecord(node.heldPoint(i))];
            }
            counted += node.pointCount;
            if (n % 1024 == 0) {
                publish(counts, counted, false);
            }
        }
    }
    if (!stop.stop_requested()) {
        publish(counts, counted, true);
        const std::lock_guard lock(m_mutex);
        m_snapshot.total = counted; // the records counted samples too: the input is the leaves'
    }
}

} // namespace omicron
