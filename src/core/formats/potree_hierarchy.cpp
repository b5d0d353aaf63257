#include "formats/potree_hierarchy.hpp"

#include <algorithm>
#include <cstring>
#include <deque>

namespace omicron {

namespace {

enum PotreeNodeType : std::uint8_t { kNormal = 0, kLeaf = 1, kProxy = 2 };
constexpr std::size_t kRecordBytes = 22;

template <typename T> void store(std::uint8_t* at, const T& value) {
    std::memcpy(at, &value, sizeof(T));
}

// omicron octant (z << 2 | y << 1 | x) -> Potree child index (x << 2 | y << 1 | z).
unsigned potreeChildIndex(morton::Code code) {
    const unsigned octant = static_cast<unsigned>(code & 7u);
    return ((octant & 1u) << 2) | (octant & 2u) | ((octant >> 2) & 1u);
}

struct NodeRef {
    int level = 0;
    std::uint32_t index = 0;
};

class Layout {
public:
    Layout(const Hierarchy& hierarchy, const std::vector<std::vector<PotreeNodePoints>>& points)
        : m_hierarchy(hierarchy), m_points(points) {
        // Points in each subtree, bottom-up: a subtree without any is not written.
        m_subtree.resize(points.size());
        for (int level = static_cast<int>(points.size()) - 1; level >= 0; --level) {
            auto& totals = m_subtree[static_cast<std::size_t>(level)];
            totals.resize(points[static_cast<std::size_t>(level)].size());
            for (std::size_t i = 0; i < totals.size(); ++i) {
                totals[i] = points[static_cast<std::size_t>(level)][i].count;
                const OctreeNode& node = hierarchy.node(level, i);
                for (std::uint32_t c = 0; c < node.childCount; ++c) {
                    totals[i] +=
                        m_subtree[static_cast<std::size_t>(level) + 1][node.firstChild + c];
                }
            }
        }
    }

    // A node's written children, in Potree's child-index order.
    std::vector<NodeRef> children(NodeRef ref) const {
        const OctreeNode& node = m_hierarchy.node(ref.level, ref.index);
        std::vector<NodeRef> children;
        for (std::uint32_t c = 0; c < node.childCount; ++c) {
            const NodeRef child{ref.level + 1, node.firstChild + c};
            if (subtreePoints(child) > 0) {
                children.push_back(child);
            }
        }
        std::sort(children.begin(), children.end(),
                  [&](NodeRef a, NodeRef b) { return childIndex(a) < childIndex(b); });
        return children;
    }

    unsigned childIndex(NodeRef ref) const {
        return potreeChildIndex(m_hierarchy.node(ref.level, ref.index).code);
    }
    std::uint64_t subtreePoints(NodeRef ref) const {
        return m_subtree[static_cast<std::size_t>(ref.level)][ref.index];
    }
    const PotreeNodePoints& points(NodeRef ref) const {
        return m_points[static_cast<std::size_t>(ref.level)][ref.index];
    }

private:
    const Hierarchy& m_hierarchy;
    const std::vector<std::vector<PotreeNodePoints>>& m_points;
    std::vector<std::vector<std::uint64_t>> m_subtree;
};

struct ChunkRecord {
    NodeRef node;
    PotreeNodeType type = kNormal;
    std::uint8_t childMask = 0;
    std::size_t proxyChunk = 0; // for proxies: the chunk that starts with this node
};

} // namespace

PotreeHierarchyFile layoutPotreeHierarchy(const Hierarchy& hierarchy,
                                          const std::vector<std::vector<PotreeNodePoints>>& points,
                                          std::size_t recordBytes, int stepSize) {
    const Layout layout(hierarchy, points);
    PotreeHierarchyFile file;
    // Chunks are laid out first (their sizes give the proxies' offsets), then written in order.
    std::vector<std::vector<ChunkRecord>> chunks;
    std::deque<NodeRef> chunkRoots{{0, 0}};
    while (!chunkRoots.empty()) {
        const NodeRef root = chunkRoots.front();
        chunkRoots.pop_front();
        std::vector<ChunkRecord> records;
        std::deque<NodeRef> queue{root};
        while (!queue.empty()) {
            const NodeRef ref = queue.front();
            queue.pop_front();
            const std::vector<NodeRef> children = layout.children(ref);
            ChunkRecord record{ref, children.empty() ? kLeaf : kNormal, 0, 0};
            for (NodeRef child : children) {
                record.childMask =
                    static_cast<std::uint8_t>(record.childMask | (1u << layout.childIndex(child)));
            }
            if (!children.empty() && ref.level - root.level == stepSize) {
                record.type = kProxy;
                record.proxyChunk = chunks.size() + 1 + chunkRoots.size();
                chunkRoots.push_back(ref);
            } else {
                queue.insert(queue.end(), children.begin(), children.end());
                ++file.nodes;
                file.depth = std::max(file.depth, ref.level);
            }
            records.push_back(record);
        }
        chunks.push_back(std::move(records));
    }
    std::vector<std::uint64_t> chunkOffsets(chunks.size() + 1, 0);
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        chunkOffsets[c + 1] = chunkOffsets[c] + chunks[c].size() * kRecordBytes;
    }
    file.bytes.resize(chunkOffsets.back());
    std::uint8_t* at = file.bytes.data();
    for (const auto& chunk : chunks) {
        for (const ChunkRecord& record : chunk) {
            const PotreeNodePoints& stored = layout.points(record.node);
            const bool proxy = record.type == kProxy;
            store(at + 0, static_cast<std::uint8_t>(record.type));
            store(at + 1, record.childMask);
            // A proxy announces its node's points too: loaders count them before they fetch
            // the chunk that describes it.
            store(at + 2, stored.count);
            store(at + 6, proxy ? chunkOffsets[record.proxyChunk] : stored.byteOffset);
            store(at + 14,
                  proxy ? chunkOffsets[record.proxyChunk + 1] - chunkOffsets[record.proxyChunk]
                        : std::uint64_t{stored.count} * recordBytes);
            at += kRecordBytes;
        }
    }
    file.firstChunkSize = chunkOffsets[1];
    file.chunks = chunks.size();
    return file;
}

} // namespace omicron
