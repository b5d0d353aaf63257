// Node points of a .omh loaded on demand under a memory budget: the viewer's side of a saved
// hierarchy larger than memory (pipeline 3 beyond memory), as Potree's viewer does it.
//
// The hierarchy's nodes (32 bytes each in the file) are all loaded, level by level, by
// OmhReader; their points are not. The records of a node are one contiguous range of the file
// (.omh groups records by node, level by level: the paper's horizontal cuts), so loading a
// node is one read. The front asks for nodes (NodeResidency::want, the largest on screen
// first) and keeps drawing what it holds until they are resident; a loader thread reads them
// into the hierarchy's node-order cloud, whose arrays reserve address space for every point
// but take memory only where a node was written (ResidentPages gives it back on eviction).
// After each frame the least recently used nodes the front neither holds nor wants are
// evicted until the resident points fit the budget.
//
// Threads and states. Per node: Absent -> Queued (render thread: want) -> Loading (loader) ->
// Resident (loader, release store) -> Absent (render thread: eviction). Each frame's requests
// replace the previous frame's (endFrame), largest on screen first: a Queued node the front
// stopped asking for goes back to Absent there, so the loader works on what the camera sees
// now and the request list is never longer than one frame's. The render thread reads a node's
// points only while it sees Resident (acquire), and only it evicts, so a node is never
// released under a reader; the loader writes only a Loading node, which nobody reads. One
// front per paged hierarchy (it owns the frame count).
//
// Errors: a node whose records cannot be read (the file shrank) or break the format (a
// position outside the node's cell) becomes Failed: never drawn, its parent stays in the
// front; the first such error is kept in stats().firstError, naming the file, the byte and
// the section. The payload checksums cover whole levels, so a paged load checks records one
// by one instead; `omicron-cli info --verify` checks every checksum.
#pragma once

#include "build/hierarchy.hpp"
#include "build/node_residency.hpp"
#include "formats/omh_format.hpp"
#include "formats/omh_record_decoder.hpp"
#include "io/file_stream.hpp"
#include "points/resident_pages.hpp"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace omicron {

class OmhPager final : public NodeResidency {
public:
    // Bytes a point takes in memory (cloud attributes, and splat attributes before version 3).
    static std::uint64_t residentBytesPerPoint(const omh::Header& header);

    // `cloud` and `hierarchy` are the ones OmhReader made for `header`'s file (a cloud with
    // PageSize::Small); the hierarchy owns the pager (Hierarchy::setResidency). Starts the
    // loader thread.
    OmhPager(const omh::Header& header, std::shared_ptr<SortedCloud> cloud, Hierarchy& hierarchy,
             std::uint64_t budgetBytes);
    ~OmhPager() override; // stops and joins the loader

    bool resident(int level, std::uint32_t index) const override;
    bool want(int level, std::uint32_t index, double priority) override;
    void hold(int level, std::uint32_t index) override;
    void endFrame() override;
    ResidencyStats stats() const override;
    const std::string& backingFile() const override { return m_header.path; }

private:
    enum State : std::uint8_t { Absent, Queued, Loading, Resident, Failed };

    struct Request {
        double priority = 0.0; // larger first
        int level = 0;
        std::uint32_t index = 0;
    };

    std::uint64_t nodeId(int level, std::uint32_t index) const {
        return m_levelBase[static_cast<std::size_t>(level)] + index;
    }
    // Render thread, end of a frame: this frame's requests replace the last frame's.
    void publishRequests(std::uint32_t frame);
    void loaderLoop();
    void load(int level, std::uint32_t index);
    // Version 3: reads the stored splat attributes of `node`, a sparse node of `level`.
    void loadSparseSplats(int level, std::uint32_t index, const OctreeNode& node);
    void evict(int level, std::uint32_t index);
    void fail(std::uint64_t id, const std::string& error);

    omh::Header m_header;
    std::uint64_t m_bytesPerPoint;
    std::uint64_t m_budget;
    std::shared_ptr<SortedCloud> m_cloud;
    Hierarchy& m_hierarchy;
    std::vector<std::uint64_t> m_levelBase;  // first node id of each level
    std::vector<std::uint64_t> m_levelFirst; // first record of each level
    ResidentPages m_pages;
    FileStream m_stream;                // the loader's
    OmhRecordDecoder m_decoder;         // the loader's
    std::vector<std::uint8_t> m_records; // the loader's
    // Version 3, the loader's: per level (filled at its first load), the points of the sparse
    // nodes before each node, where its splat attributes are among the level's.
    std::vector<std::vector<std::uint64_t>> m_sparseBefore;

    std::unique_ptr<std::atomic<std::uint8_t>[]> m_state;
    std::vector<std::uint32_t> m_wantedFrame; // render thread: the last frame that asked
    std::vector<std::uint32_t> m_lastUsed;     // render thread: last frame held or wanted
    struct NodeRef {
        int level = 0;
        std::uint32_t index = 0;
    };
    std::vector<NodeRef> m_residentList; // render thread's view of the resident nodes (any order)
    std::vector<Request> m_frameRequests; // render thread: the Queued nodes this frame asked for
    std::uint32_t m_frame = 1; // render thread
    std::uint64_t m_heldBytes = 0; // render thread, this frame
    std::atomic<std::uint64_t> m_lastHeldBytes{0};

    mutable std::mutex m_mutex; // the queue, the new residents, the error
    std::condition_variable m_wake;
    // The last frame's requests, smallest priority first (the loader takes from the back);
    // each frame's replace the previous ones, so it holds at most what one frame asked for.
    std::vector<Request> m_requests;
    std::vector<NodeRef> m_newlyResident; // loaded since the render thread last looked
    std::string m_firstError;
    bool m_stop = false;

    std::atomic<std::uint64_t> m_residentBytes{0};
    std::atomic<std::uint64_t> m_residentNodes{0};
    std::atomic<std::uint64_t> m_loads{0};
    std::atomic<std::uint64_t> m_evictions{0};
    std::atomic<std::uint64_t> m_bytesRead{0};
    std::atomic<std::uint64_t> m_pending{0}; // Queued or Loading
    std::atomic<std::uint64_t> m_failed{0};

    std::thread m_loader; // last: started when everything above exists
};

} // namespace omicron
