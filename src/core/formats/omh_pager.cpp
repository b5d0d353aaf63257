#include "formats/omh_pager.hpp"

#include "formats/omh_reader.hpp"
#include "formats/omh_record_decoder.hpp"
#include "io/input_error.hpp"

#include <algorithm>

namespace omicron {

namespace {

// Over the budget, eviction goes this far below it, so that loads do not evict one node each.
constexpr double kEvictTo = 0.875;

} // namespace

std::uint64_t OmhPager::residentBytesPerPoint(const omh::Header& header) {
    // The cloud's point (but its uniform columns, stored once), then before version 3 the
    // stored splat radius and estimated normal. From version 3 only the few points of sparse
    // nodes have them stored; the others' are estimated when drawn, into the renderer's
    // buffers, and their pages of the splat arrays are never touched.
    return pointBytes(omh::recordAttributes(header.attributes, header.uniformColumns)) +
           (header.splatsInRecords() ? header.splatBytes() : 0);
}

OmhPager::OmhPager(const omh::Header& header, std::shared_ptr<SortedCloud> cloud,
                   Hierarchy& hierarchy, std::uint64_t budgetBytes)
    : m_header(header), m_bytesPerPoint(residentBytesPerPoint(header)), m_budget(budgetBytes),
      m_cloud(std::move(cloud)), m_hierarchy(hierarchy), m_stream(header.path),
      m_decoder(m_header, *m_cloud, hierarchy.mutableStoredSplats()),
      m_state(std::make_unique<std::atomic<std::uint8_t>[]>(header.totalNodes)),
      m_wantedFrame(header.totalNodes, 0), m_lastUsed(header.totalNodes, 0) {
    std::uint64_t base = 0, first = 0;
    for (const omh::LevelEntry& level : header.levels) {
        m_levelBase.push_back(base);
        m_levelFirst.push_back(first);
        base += level.nodes;
        first += level.points;
    }
    SortedCloud& c = *m_cloud;
    const std::size_t n = c.capacity();
    m_pages.addArray(c.mutablePositions().data(), sizeof(glm::vec3), c.mutablePositions().size());
    m_pages.addArray(c.mutableNormals().data(), sizeof(glm::vec3), c.mutableNormals().size());
    m_pages.addArray(c.mutableColors().data(), sizeof(glm::u8vec3), c.mutableColors().size());
    // A uniform column's one value is never paged out.
    m_pages.addArray(c.mutableIntensities().data(), sizeof(std::uint16_t),
                     c.uniformIntensities() ? 0 : c.mutableIntensities().size());
    m_pages.addArray(c.mutableLasColumn().data(), c.attributes().lasBytes(),
                     c.mutableLasColumn().empty() || c.uniformLasColumn() ? 0 : n);
    StoredSplats& splats = hierarchy.mutableStoredSplats();
    m_pages.addArray(splats.mutableRadii().data(), sizeof(std::uint16_t), n);
    m_pages.addArray(splats.mutableNormals().data(), sizeof(std::uint32_t),
                     splats.mutableNormals().size());
    m_loader = std::thread([this] { loaderLoop(); });
}

OmhPager::~OmhPager() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
    }
    m_wake.notify_all();
    m_loader.join();
}

bool OmhPager::resident(int level, std::uint32_t index) const {
    return m_state[nodeId(level, index)].load(std::memory_order_acquire) == Resident;
}

bool OmhPager::want(int level, std::uint32_t index, double priority) {
    const std::uint64_t id = nodeId(level, index);
    const std::uint32_t frame = m_frame;
    m_lastUsed[id] = frame;
    std::uint8_t state = m_state[id].load(std::memory_order_acquire);
    if (state == Resident) {
        return true;
    }
    if (state == Absent) {
        if (!m_state[id].compare_exchange_strong(state, Queued)) {
            return state == Resident;
        }
        m_pending.fetch_add(1, std::memory_order_relaxed);
    } else if (state != Queued) {
        return false; // loading or failed
    }
    if (m_wantedFrame[id] != frame) { // once a frame
        m_wantedFrame[id] = frame;
        m_frameRequests.push_back(Request{priority, level, index});
    }
    return false;
}

void OmhPager::hold(int level, std::uint32_t index) {
    const std::uint64_t id = nodeId(level, index);
    m_lastUsed[id] = m_frame;
    m_heldBytes += std::uint64_t{m_hierarchy.node(level, index).pointCount} * m_bytesPerPoint;
}

void OmhPager::publishRequests(std::uint32_t frame) {
    std::sort(m_frameRequests.begin(), m_frameRequests.end(),
              [](const Request& a, const Request& b) { return a.priority < b.priority; });
    {
        std::lock_guard lock(m_mutex);
        m_requests.swap(m_frameRequests);
    }
    // The previous frame's requests that this one did not repeat: the camera moved on. The
    // loader may have taken one already (Loading): the exchange leaves it alone.
    for (const Request& old : m_frameRequests) {
        const std::uint64_t id = nodeId(old.level, old.index);
        std::uint8_t queued = Queued;
        if (m_wantedFrame[id] != frame && m_state[id].compare_exchange_strong(queued, Absent)) {
            m_pending.fetch_sub(1, std::memory_order_relaxed);
        }
    }
    m_frameRequests.clear();
    m_wake.notify_one();
}

void OmhPager::endFrame() {
    const std::uint32_t frame = m_frame;
    publishRequests(frame);
    {
        std::lock_guard lock(m_mutex);
        m_residentList.insert(m_residentList.end(), m_newlyResident.begin(), m_newlyResident.end());
        m_newlyResident.clear();
    }
    if (m_residentBytes.load(std::memory_order_relaxed) > m_budget) {
        // The nodes this frame neither held nor wanted, least recently used first.
        const auto lastUsed = [&](const NodeRef& node) {
            return m_lastUsed[nodeId(node.level, node.index)];
        };
        const auto unused =
            std::partition(m_residentList.begin(), m_residentList.end(),
                           [&](const NodeRef& node) { return lastUsed(node) >= frame; });
        std::sort(unused, m_residentList.end(),
                  [&](const NodeRef& a, const NodeRef& b) { return lastUsed(a) < lastUsed(b); });
        const auto target = static_cast<std::uint64_t>(static_cast<double>(m_budget) * kEvictTo);
        auto kept = unused;
        for (; kept != m_residentList.end() &&
               m_residentBytes.load(std::memory_order_relaxed) > target;
             ++kept) {
            evict(kept->level, kept->index);
        }
        m_residentList.erase(unused, kept);
    }
    m_lastHeldBytes.store(m_heldBytes, std::memory_order_relaxed);
    m_heldBytes = 0;
    m_frame = frame + 1;
}

void OmhPager::evict(int level, std::uint32_t index) {
    const OctreeNode& node = m_hierarchy.node(level, index);
    // Only this thread reads points, and it stops now: no reader is left when they go.
    m_state[nodeId(level, index)].store(Absent, std::memory_order_relaxed);
    m_pages.release(node.coveredBegin, std::size_t{node.coveredBegin} + node.pointCount);
    m_residentBytes.fetch_sub(std::uint64_t{node.pointCount} * m_bytesPerPoint,
                              std::memory_order_relaxed);
    m_residentNodes.fetch_sub(1, std::memory_order_relaxed);
    m_evictions.fetch_add(1, std::memory_order_relaxed);
}

void OmhPager::loaderLoop() {
    for (;;) {
        Request request;
        {
            std::unique_lock lock(m_mutex);
            m_wake.wait(lock, [&] { return m_stop || !m_requests.empty(); });
            if (m_stop) {
                return;
            }
            request = m_requests.back();
            m_requests.pop_back();
        }
        std::uint8_t queued = Queued;
        if (m_state[nodeId(request.level, request.index)].compare_exchange_strong(queued,
                                                                                  Loading)) {
            load(request.level, request.index);
        }
    }
}

void OmhPager::load(int level, std::uint32_t index) {
    const std::uint64_t id = nodeId(level, index);
    const OctreeNode& node = m_hierarchy.node(level, index);
    const std::size_t begin = node.coveredBegin;
    const std::size_t count = node.pointCount;
    const omh::LevelEntry& entry = m_header.levels[static_cast<std::size_t>(level)];
    const std::uint64_t inLevel = begin - m_levelFirst[static_cast<std::size_t>(level)];
    m_pages.acquire(begin, begin + count);
    try {
        std::size_t bad = 0;
        if (m_header.columnar(entry)) { // version 4's deepest level: a read per column
            m_decoder.readColumns(m_stream, level, inLevel, count, begin, nullptr);
            bad = m_decoder.firstMisplaced(begin, count, node.code, level);
        } else {
            const std::uint64_t offset = entry.payloadOffset + inLevel * m_header.recordBytes;
            m_records.resize(count * m_header.recordBytes);
            m_stream.seek(offset);
            m_stream.readExact(m_records.data(), m_records.size(), omhSectionAt(m_header, offset));
            bad = m_decoder.store(m_records.data(), count, begin, node.code, level);
        }
        if (bad != count) {
            throw m_decoder.misplaced(level, inLevel + bad, node.code);
        }
        if (!m_header.splatsInRecords() && omh::storesSplats(count)) {
            loadSparseSplats(level, index, node);
        }
    } catch (const InputError& error) {
        m_pages.release(begin, begin + count);
        fail(id, error.what());
        return;
    }
    m_bytesRead.fetch_add(count * m_header.recordBytes, std::memory_order_relaxed);
    m_residentBytes.fetch_add(count * m_bytesPerPoint, std::memory_order_relaxed);
    m_residentNodes.fetch_add(1, std::memory_order_relaxed);
    m_loads.fetch_add(1, std::memory_order_relaxed);
    {
        std::lock_guard lock(m_mutex);
        m_newlyResident.push_back(NodeRef{level, index});
    }
    m_state[id].store(Resident, std::memory_order_release);
    m_pending.fetch_sub(1, std::memory_order_relaxed);
}

void OmhPager::loadSparseSplats(int level, std::uint32_t index, const OctreeNode& node) {
    const auto l = static_cast<std::size_t>(level);
    const omh::LevelEntry& entry = m_header.levels[l];
    if (m_sparseBefore.empty()) {
        m_sparseBefore.resize(m_header.levels.size());
    }
    std::vector<std::uint64_t>& before = m_sparseBefore[l];
    if (before.empty()) { // the level's nodes are all published: this one was asked for
        before.resize(entry.nodes);
        std::uint64_t points = 0;
        for (std::size_t i = 0; i < entry.nodes; ++i) {
            before[i] = points;
            const std::uint32_t count = m_hierarchy.node(level, i).pointCount;
            points += omh::storesSplats(count) ? count : 0;
        }
    }
    const std::size_t splatBytes = m_header.splatBytes();
    const std::uint64_t offset = m_header.sparseSplatsOffset(entry) + before[index] * splatBytes;
    m_records.resize(std::size_t{node.pointCount} * splatBytes);
    m_stream.seek(offset);
    m_stream.readExact(m_records.data(), m_records.size(), omhSectionAt(m_header, offset));
    m_decoder.storeSparseSplats(m_records.data(), node.pointCount, node.coveredBegin);
    m_bytesRead.fetch_add(m_records.size(), std::memory_order_relaxed);
}

void OmhPager::fail(std::uint64_t id, const std::string& error) {
    {
        std::lock_guard lock(m_mutex);
        if (m_firstError.empty()) {
            m_firstError = error;
        }
    }
    m_failed.fetch_add(1, std::memory_order_relaxed);
    m_state[id].store(Failed, std::memory_order_release);
    m_pending.fetch_sub(1, std::memory_order_relaxed);
}

ResidencyStats OmhPager::stats() const {
    ResidencyStats stats;
    stats.budgetBytes = m_budget;
    stats.residentBytes = m_residentBytes.load(std::memory_order_relaxed);
    stats.residentNodes = m_residentNodes.load(std::memory_order_relaxed);
    stats.heldBytes = m_lastHeldBytes.load(std::memory_order_relaxed);
    stats.loads = m_loads.load(std::memory_order_relaxed);
    stats.evictions = m_evictions.load(std::memory_order_relaxed);
    stats.bytesRead = m_bytesRead.load(std::memory_order_relaxed);
    stats.pendingLoads = m_pending.load(std::memory_order_relaxed);
    stats.failedNodes = m_failed.load(std::memory_order_relaxed);
    std::lock_guard lock(m_mutex);
    stats.firstError = m_firstError;
    return stats;
}

} // namespace omicron
