// GPU vertex buffers of hierarchy nodes, uploaded on the GUI thread within a per-frame byte
// budget and evicted least-recently-drawn first when a GPU memory budget is exceeded (nodes
// that left the front are the ones that stop being drawn).
//
// Nodes live as ranges of a few large buffers ("pages") rather than one buffer each: GL_POINTS
// draws a range (glDrawArrays' first), and the compute point rasterizer reads a whole page (a
// buffer texture over it) and rasterizes every drawn node in it with one dispatch. One buffer
// per node would cost a dispatch per node, and a dispatch is a thread-pool round trip on Mesa
// llvmpipe (measured with render_bench on the bunny: frames 15 to 60 times slower that way).
#pragma once

#include "node_vertices.hpp"

#include <QOpenGLExtraFunctions>
#include <cstddef>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

namespace omicron {

class NodeBufferCache {
public:
    using Key = std::uint64_t;
    static Key key(int level, std::uint32_t index) {
        return (static_cast<Key>(level) << 32) | index;
    }

    // Points per page (24 MiB of vertices at 1 << 20); a node larger than a page gets a page
    // of its own size.
    static constexpr std::size_t kDefaultPagePoints = std::size_t{1} << 20;

    struct Buffer {
        unsigned vbo = 0;   // the page's buffer
        int firstPoint = 0; // where the node's vertices start in it
        int pointCount = 0;
        std::size_t bytes = 0;
        std::uint64_t lastUsedFrame = 0;
    };

    // Page size for pages created from now on (the compute rasterizer reads a page through
    // one buffer texture, so it must not exceed GL_MAX_TEXTURE_BUFFER_SIZE).
    void setPagePoints(std::size_t points) { m_pagePoints = points > 0 ? points : 1; }

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
        m_pages.clear();
        m_freeBySize.clear();
        m_bytes = 0;
    }

    // Bytes of node vertices resident (pages hold some free space besides).
    std::size_t bytesResident() const { return m_bytes; }
    std::size_t size() const { return m_buffers.size(); }
    std::size_t pageCount() const { return m_pages.size(); }

private:
    struct Page {
        unsigned vbo = 0;
        std::size_t capacityPoints = 0;
        std::size_t usedPoints = 0;
        std::map<std::size_t, std::size_t> freeRanges; // first point -> points, coalesced
    };

    // Best fit over the pages' free ranges, else a new page. Returns its vbo and first point.
    std::pair<unsigned, std::size_t> allocate(QOpenGLExtraFunctions& gl, std::size_t points);
    void free(QOpenGLExtraFunctions& gl, const Buffer& buffer);
    void addFreeRange(Page& page, std::size_t first, std::size_t points);
    void removeFreeRange(Page& page, std::map<std::size_t, std::size_t>::iterator range);

    std::unordered_map<Key, Buffer> m_buffers;
    std::unordered_map<unsigned, Page> m_pages; // by vbo
    // Every page's free ranges by size (points -> vbo, first point), for best fit.
    std::multimap<std::size_t, std::pair<unsigned, std::size_t>> m_freeBySize;
    std::size_t m_pagePoints = kDefaultPagePoints;
    std::size_t m_bytes = 0;
};

} // namespace omicron
