// Which nodes of a hierarchy have their points in memory, for a hierarchy whose points are
// paged in on demand (a .omh larger than the memory budget: formats/omh_pager.hpp).
//
// A hierarchy without one has every published node's points in memory. With one, the render
// front (front/front.hpp) keeps the rule "never draw a node whose points are missing" by
// asking before it changes what it draws: it branches into children only once all of them are
// resident, prunes a group into its parent only once the parent is, and asks for the missing
// ones meanwhile, so the nodes it already holds (an ancestor) stay drawn until they arrive.
// The interface lives here, below the front and the formats, so that neither depends on the
// other: the front asks, the .omh pager answers.
//
// Threads: every member but stats() is called by the one render thread that owns the front
// (one front per paged hierarchy); the implementation loads on threads of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace omicron {

// What the pager holds and has done; any thread.
struct ResidencyStats {
    std::uint64_t budgetBytes = 0;   // what the resident points may take
    std::uint64_t residentBytes = 0; // the points and splat attributes in memory now
    std::uint64_t residentNodes = 0;
    std::uint64_t heldBytes = 0; // of residentBytes: the nodes the front held in its last frame
    std::uint64_t loads = 0;     // nodes read from the file
    std::uint64_t evictions = 0; // nodes given back
    std::uint64_t bytesRead = 0;
    std::uint64_t pendingLoads = 0; // nodes asked for and not loaded yet
    std::uint64_t failedNodes = 0;  // nodes whose records were unreadable (never drawn)
    std::string firstError;         // what the first failure was (file, byte, what is wrong)
};

class NodeResidency {
public:
    virtual ~NodeResidency() = default;

    // True when the points (and splat attributes) of node `index` of `level`, a published
    // node, may be read now by the calling render thread.
    virtual bool resident(int level, std::uint32_t index) const = 0;
    // The front needs this node's points (to draw it next): keeps it from eviction in this
    // frame and, when it is not resident, asks for it; `priority` orders the loads of one
    // frame, larger first (the node's projected size in pixels). Returns resident().
    virtual bool want(int level, std::uint32_t index, double priority) = 0;
    // The node is in the front (drawn now or kept): it is not evicted before the frame after
    // the next one that does not hold it. Only for resident nodes.
    virtual void hold(int level, std::uint32_t index) = 0;
    // After an evaluation: gives back nodes neither held nor wanted in this frame, least
    // recently used first, until the resident points fit the budget; starts the next frame.
    virtual void endFrame() = 0;

    virtual ResidencyStats stats() const = 0;

    // The file the points are read from (a writer that needs every point copies from it).
    virtual const std::string& backingFile() const = 0;
};

} // namespace omicron
