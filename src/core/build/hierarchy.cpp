#include "build/hierarchy.hpp"

#include "build/leaf_runs.hpp"

#include <algorithm>
#include <cassert>

namespace omicron {

Hierarchy::Hierarchy(std::shared_ptr<const SortedCloud> cloud, int maxLevel,
                     SplatSource splatSource)
    : m_cloud(std::move(cloud)), m_maxLevel(maxLevel), m_insertions(m_cloud->capacity()),
      m_storedSplats(splatSource != SplatSource::Estimated
                         ? std::make_unique<StoredSplats>(
                               *m_cloud, splatSource == SplatSource::StoredForSparseNodes)
                         : nullptr) {
    assert(maxLevel >= 0 && maxLevel <= morton::kMaxLevel);
    m_levels.reserve(static_cast<std::size_t>(maxLevel) + 1);
    for (int level = 0; level <= maxLevel; ++level) {
        // Every node covers at least one point, and a level has at most 8^level cells.
        const std::uint64_t cells = std::uint64_t{1} << (3 * level);
        const std::size_t capacity =
            static_cast<std::size_t>(std::min<std::uint64_t>(cells, m_cloud->capacity()));
        m_levels.push_back(std::make_unique<Level>(capacity));
    }
}

std::optional<std::size_t> Hierarchy::findNode(morton::Code code, std::size_t count) const {
    const int level = morton::level(code);
    if (level > m_maxLevel) {
        return std::nullopt;
    }
    const auto& nodes = m_levels[level]->nodes;
    std::size_t low = 0, high = count;
    while (low < high) {
        const std::size_t mid = low + (high - low) / 2;
        if (nodes[mid].code < code) {
            low = mid + 1;
        } else {
            high = mid;
        }
    }
    if (low < count && nodes[low].code == code) {
        return low;
    }
    return std::nullopt;
}

void Hierarchy::nodeSplats(const OctreeNode& node, NodeSplats& out, SplatScratch& scratch) const {
    if (!m_storedSplats ||
        (m_storedSplats->sparseNodesOnly() && node.pointCount >= kMinPointsPerSplatEstimate)) {
        // Finding the region costs two searches of the cloud: only for the nodes that use it.
        const SparseSplatRegion region = node.pointCount < kMinPointsPerSplatEstimate
                                             ? sparseSplatRegion(node)
                                             : SparseSplatRegion{};
        estimateNodeSplats(*m_cloud, node, region, estimatesNormals(), out, scratch);
        return;
    }
    out.radii.resize(node.pointCount);
    out.normals.resize(m_storedSplats->estimatesNormals() ? node.pointCount : 0);
    for (std::uint32_t i = 0; i < node.pointCount; ++i) {
        out.radii[i] = m_storedSplats->encodedRadius(node.heldPoint(i));
    }
    for (std::uint32_t i = 0; i < out.normals.size(); ++i) {
        out.normals[i] = m_storedSplats->encodedNormal(node.heldPoint(i));
    }
}

SparseSplatRegion Hierarchy::sparseSplatRegion(const OctreeNode& node) const {
    if (!node.holdsRange()) {
        return {node.coveredBegin, node.coveredCount, node.pointCount};
    }
    if (node.level() != m_maxLevel || m_maxLevel == 0 || node.pointCount == 0) {
        return {node.coveredBegin, node.coveredCount, node.coveredCount};
    }
    const int groupLevel = m_maxLevel - 1;
    return m_cloud->visitPositions([&](const auto& positions) -> SparseSplatRegion {
        const std::size_t begin = startOfRun(positions, node.coveredBegin, groupLevel);
        const std::size_t end =
            endOfRun(positions, node.coveredBegin, m_cloud->sortedEnd(), groupLevel);
        const auto count = static_cast<std::uint32_t>(end - begin);
        return {static_cast<std::uint32_t>(begin), count, count};
    });
}

PublishedCut Hierarchy::publishedCut() const {
    PublishedCut cut;
    cut.complete = m_complete.load(std::memory_order_acquire);
    cut.epoch = m_epoch.load(std::memory_order_acquire);
    cut.delimiter = m_cutDelimiter.load(std::memory_order_acquire);
    for (int level = 1; level <= m_maxLevel; ++level) {
        cut.fixedThrough[level] = fixedThrough(level);
    }
    return cut;
}

bool Hierarchy::isSettled(morton::Code code, const PublishedCut& cut, int maxLevel) {
    if (cut.complete) {
        return true;
    }
    const int level = morton::level(code);
    return level >= 2 && cut.fixedThrough[level - 1] != 0 &&
           morton::span(code >> 6, maxLevel) <= cut.fixedThrough[level - 1];
}

std::size_t Hierarchy::appendNode(int level, const OctreeNode& node) {
    auto& nodes = m_levels[level]->nodes;
    assert(node.level() == level);
    assert(nodes.size() == 0 || nodes[nodes.size() - 1].code < node.code);
    return nodes.push_back(node);
}

void Hierarchy::publishNodes(int level) {
    Level& storage = *m_levels[level];
    const std::size_t published = storage.published.load(std::memory_order_relaxed);
    if (published != storage.nodes.size()) {
#ifndef NDEBUG
        // Nodes filled through builtNode() are checked here, before anyone can see them.
        for (std::size_t i = published; i < storage.nodes.size(); ++i) {
            assert(storage.nodes[i].level() == level);
            assert(i == 0 || storage.nodes[i - 1].code < storage.nodes[i].code);
        }
#endif
        storage.published.store(storage.nodes.size(), std::memory_order_release);
        bumpEpoch();
    }
}

void Hierarchy::publishInsertions() {
    auto& entries = m_insertions.entries;
    const std::size_t published = m_insertions.published.load(std::memory_order_relaxed);
    if (published != entries.size()) {
#ifndef NDEBUG
        for (std::size_t i = std::max<std::size_t>(published, 1); i < entries.size(); ++i) {
            assert(morton::span(entries[i - 1].leafCode, m_maxLevel) <
                   morton::span(entries[i].leafCode, m_maxLevel));
        }
#endif
        m_insertions.published.store(entries.size(), std::memory_order_release);
        bumpEpoch();
    }
}

void Hierarchy::publishFixedThrough(int level, morton::Code delimiter) {
    m_levels[level]->fixedThrough.store(delimiter, std::memory_order_release);
}

void Hierarchy::publishCutDelimiter(morton::Code delimiter) {
    m_cutDelimiter.store(delimiter, std::memory_order_release);
    bumpEpoch();
}

void Hierarchy::markComplete() {
    m_complete.store(true, std::memory_order_release);
    bumpEpoch();
}

std::size_t Hierarchy::nodeBytes() const {
    std::size_t bytes = 0;
    for (const auto& level : m_levels) {
        bytes += level->nodes.bytesAllocated();
    }

    return bytes;
}

} // namespace omicron
