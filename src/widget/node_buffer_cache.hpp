// GPU vertex buffers of hierarchy nodes, uploaded on the GUI thread within a per-frame byte
// budget and evicted least-recently-drawn first when a GPU memory budget is exceeded (nodes
// that left the front are the ones that stop being drawn).
#pragma once

#include "node_vertices.hpp"

#include <QOpenGLExtraFunctions>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace omicron {

class NodeBufferCache {
public:
    using Key = std::uint64_t;
    static Key key(int level, std::uint32_t index) {
        return (static_cast<Key>(level) << 32) | index;
    }

    struct Buffer {
        unsigned vbo = 0;
        int pointCount = 0;
        std::size_t bytes = 0;
        std::uint64_t lastUsedFrame = 0;
    };

    // nullptr when `key` is not resident; otherwise marks it used in `frame`.
    const Buffer* use(Key key, std::uint64_t frame);
    const Buffer& upload(QOpenGLExtraFunctions& gl, Key key, const std::vector<PointVertex>& vertices,
                         std::uint64_t frame);
    // Frees buffers not used in `frame`, oldest first, until at most `budgetBytes` are resident.
    std::size_t evictTo(QOpenGLExtraFunctions& gl, std::size_t budgetBytes, std::uint64_t frame);
    void clear(QOpenGLExtraFunctions& gl);
    // Forgets every buffer without GL calls (the context that owned them is gone).
    void abandon() {
        m_buffers.clear();
        m_bytes = 0;
    }

    std::size_t bytesResident() const { return m_bytes; }
    std::size_t size() const { return m_buffers.size(); }

private:
    std::unordered_map<Key, Buffer> m_buffers;
    std::size_t m_bytes = 0;
};

} // namespace omicron
