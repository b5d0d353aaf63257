#include "node_buffer_cache.hpp"

#include <algorithm>
#include <iterator>

namespace omicron {

const NodeBufferCache::Buffer* NodeBufferCache::use(Key key, std::uint64_t frame) {
    const auto found = m_buffers.find(key);
    if (found == m_buffers.end()) {
        return nullptr;
    }
    found->second.lastUsedFrame = frame;
    return &found->second;
}

void NodeBufferCache::addFreeRange(Page& page, std::size_t first, std::size_t points) {
    page.freeRanges.emplace(first, points);
    m_freeBySize.emplace(points, std::make_pair(page.vbo, first));
}

void NodeBufferCache::removeFreeRange(Page& page,
                                      std::map<std::size_t, std::size_t>::iterator range) {
    auto [bySize, end] = m_freeBySize.equal_range(range->second);
    while (bySize != end && bySize->second != std::make_pair(page.vbo, range->first)) {
        ++bySize;
    }
    m_freeBySize.erase(bySize);
    page.freeRanges.erase(range);
}

std::pair<unsigned, std::size_t> NodeBufferCache::allocate(QOpenGLExtraFunctions& gl,
                                                           std::size_t points) {
    const auto fit = m_freeBySize.lower_bound(points);
    if (fit != m_freeBySize.end()) {
        const auto [vbo, first] = fit->second;
        Page& page = m_pages.at(vbo);
        const std::size_t rest = fit->first - points;
        removeFreeRange(page, page.freeRanges.find(first));
        if (rest > 0) {
            addFreeRange(page, first + points, rest);
        }
        page.usedPoints += points;
        return {vbo, first};
    }
    Page page;
    page.capacityPoints = std::max(m_pagePoints, points);
    gl.glGenBuffers(1, &page.vbo);
    gl.glBindBuffer(GL_ARRAY_BUFFER, page.vbo);
    gl.glBufferData(GL_ARRAY_BUFFER,
                    static_cast<GLsizeiptr>(page.capacityPoints * sizeof(PointVertex)), nullptr,
                    GL_STATIC_DRAW);
    gl.glBindBuffer(GL_ARRAY_BUFFER, 0);
    page.usedPoints = points;
    const unsigned vbo = page.vbo;
    Page& stored = m_pages.emplace(vbo, std::move(page)).first->second;
    if (stored.capacityPoints > points) {
        addFreeRange(stored, points, stored.capacityPoints - points);
    }
    return {vbo, 0};
}

void NodeBufferCache::free(QOpenGLExtraFunctions& gl, const Buffer& buffer) {
    m_bytes -= buffer.bytes;
    const auto found = m_pages.find(buffer.vbo);
    if (found == m_pages.end() || buffer.pointCount == 0) {
        return;
    }
    Page& page = found->second;
    std::size_t first = static_cast<std::size_t>(buffer.firstPoint);
    std::size_t points = static_cast<std::size_t>(buffer.pointCount);
    page.usedPoints -= points;
    if (page.usedPoints == 0) {
        while (!page.freeRanges.empty()) {
            removeFreeRange(page, page.freeRanges.begin());
        }
        gl.glDeleteBuffers(1, &page.vbo);
        m_pages.erase(found);
        return;
    }
    // Coalesce with the free neighbours so large nodes still fit later.
    auto next = page.freeRanges.lower_bound(first);
    if (next != page.freeRanges.end() && first + points == next->first) {
        points += next->second;
        const auto following = std::next(next);
        removeFreeRange(page, next);
        next = following;
    }
    if (next != page.freeRanges.begin()) {
        const auto previous = std::prev(next);
        if (previous->first + previous->second == first) {
            first = previous->first;
            points += previous->second;
            removeFreeRange(page, previous);
        }
    }
    addFreeRange(page, first, points);
}

const NodeBufferCache::Buffer& NodeBufferCache::upload(QOpenGLExtraFunctions& gl, Key key,
                                                       const std::vector<PointVertex>& vertices,
                                                       std::uint64_t frame) {
    Buffer& buffer = m_buffers[key];
    free(gl, buffer); // uploaded again (another size): a new range
    buffer = Buffer{};
    buffer.bytes = vertices.size() * sizeof(PointVertex);
    buffer.pointCount = static_cast<int>(vertices.size());
    buffer.lastUsedFrame = frame;
    if (!vertices.empty()) {
        const auto [vbo, first] = allocate(gl, vertices.size());
        buffer.vbo = vbo;
        buffer.firstPoint = static_cast<int>(first);
        gl.glBindBuffer(GL_ARRAY_BUFFER, vbo);
        gl.glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(first * sizeof(PointVertex)),
                           static_cast<GLsizeiptr>(buffer.bytes), vertices.data());
        gl.glBindBuffer(GL_ARRAY_BUFFER, 0);
    }
    m_bytes += buffer.bytes;
    return buffer;
}

std::size_t NodeBufferCache::evictTo(QOpenGLExtraFunctions& gl, std::size_t budgetBytes,
                                     std::uint64_t frame) {
    if (m_bytes <= budgetBytes) {
        return 0;
    }
    std::vector<std::pair<std::uint64_t, Key>> candidates;
    for (const auto& [key, buffer] : m_buffers) {
        if (buffer.lastUsedFrame < frame) {
            candidates.emplace_back(buffer.lastUsedFrame, key);
        }
    }
    std::sort(candidates.begin(), candidates.end());
    std::size_t evicted = 0;
    for (const auto& [lastUsed, key] : candidates) {
        if (m_bytes <= budgetBytes) {
            break;
        }
        const auto found = m_buffers.find(key);
        free(gl, found->second);
        m_buffers.erase(found);
        ++evicted;
    }
    return evicted;
}

void NodeBufferCache::clear(QOpenGLExtraFunctions& gl) {
    for (auto& [vbo, page] : m_pages) {
        gl.glDeleteBuffers(1, &page.vbo);
    }
    m_pages.clear();
    m_freeBySize.clear();
    m_buffers.clear();
    m_bytes = 0;
}

} // namespace omicron
