#include "node_buffer_cache.hpp"

#include <algorithm>

namespace omicron {

const NodeBufferCache::Buffer* NodeBufferCache::use(Key key, std::uint64_t frame) {
    const auto found = m_buffers.find(key);
    if (found == m_buffers.end()) {
        return nullptr;
    }
    found->second.lastUsedFrame = frame;
    return &found->second;
}

const NodeBufferCache::Buffer& NodeBufferCache::upload(QOpenGLExtraFunctions& gl, Key key,
                                                       const std::vector<PointVertex>& vertices,
                                                       std::uint64_t frame) {
    Buffer& buffer = m_buffers[key];
    if (buffer.vbo == 0) {
        gl.glGenBuffers(1, &buffer.vbo);
    }
    m_bytes -= buffer.bytes;
    buffer.bytes = vertices.size() * sizeof(PointVertex);
    buffer.pointCount = static_cast<int>(vertices.size());
    buffer.lastUsedFrame = frame;
    gl.glBindBuffer(GL_ARRAY_BUFFER, buffer.vbo);
    gl.glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(buffer.bytes), vertices.data(),
                    GL_STATIC_DRAW);
    gl.glBindBuffer(GL_ARRAY_BUFFER, 0);
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
        gl.glDeleteBuffers(1, &found->second.vbo);
        m_bytes -= found->second.bytes;
        m_buffers.erase(found);
        ++evicted;
    }
    return evicted;
}

void NodeBufferCache::clear(QOpenGLExtraFunctions& gl) {
    for (auto& [key, buffer] : m_buffers) {
        gl.glDeleteBuffers(1, &buffer.vbo);
    }
    m_buffers.clear();
    m_bytes = 0;
}

} // namespace omicron
