#include "compute_rasterizer.hpp"

#include "shader_library.hpp"

#include <QOpenGLContext>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>

namespace omicron {

namespace {

constexpr unsigned kLocalSize = 128;               // local_size_x of compute_points.glsl
constexpr unsigned kMaxGroupsPerDimension = 65535; // what every GL 4.3 driver dispatches
constexpr GLuint kDepthImageUnit = 0;
constexpr GLuint kColorImageUnit = 1;
constexpr GLuint kEmptyDepth = 0xffffffffu;
constexpr std::size_t kBytesPerTexel = 16; // RGBA32UI: a 32-byte point is 2 texels

bool disabledByEnvironment() {
    const char* value = std::getenv(ComputeRasterizer::kDisableEnvironmentVariable);
    return value != nullptr && *value != '\0' && std::strcmp(value, "0") != 0;
}

std::uint32_t packColor(const glm::vec3& color) {
    const auto byte = [](float value) {
        return static_cast<std::uint32_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255.0f));
    };
    return byte(color.x) | (byte(color.y) << 8) | (byte(color.z) << 16) | (255u << 24);
}

void bindBufferTexture(QOpenGLExtraFunctions& gl, GLenum unit, unsigned texture, GLenum format,
                       unsigned buffer) {
    gl.glActiveTexture(unit);
    gl.glBindTexture(GL_TEXTURE_BUFFER, texture);
    gl.glTexBuffer(GL_TEXTURE_BUFFER, format, buffer);
}

} // namespace

void ComputeRasterizer::initializeGL(QOpenGLContext& context) {
    // A new context: the old one's objects went with it.
    forgetObjects();
    m_maxPageBytes = 0;
    if (disabledByEnvironment()) {
        qInfo("omicron::CloudView: %s is set: compute points are drawn as GL points",
              kDisableEnvironmentVariable);
        return;
    }
    const QSurfaceFormat format = context.format();
    if (context.isOpenGLES() || format.version() < qMakePair(4, 3)) {
        qInfo("omicron::CloudView: OpenGL %d.%d has no compute shaders: compute points are "
              "drawn as GL points",
              format.majorVersion(), format.minorVersion());
        return;
    }
    try {
        // color.glsl in both: the depth pass drops hidden classes as the colour pass does.
        auto depth =
            buildComputeProgram("compute_depth.comp", {"color.glsl", "compute_points.glsl"});
        auto color =
            buildComputeProgram("compute_color.comp", {"color.glsl", "compute_points.glsl"});
        m_resolveProgram = buildShaderProgram({"fullscreen.vert", "compute_resolve.frag"});
        m_colorProgram = std::move(color);
        m_depthProgram = std::move(depth);
    } catch (const std::exception& error) {
        m_resolveProgram.reset();
        qWarning("omicron::CloudView: compute points unavailable, drawn as GL points: %s",
                 error.what());
        return;
    }
    QOpenGLExtraFunctions& gl = *context.extraFunctions();
    GLint maxTexels = 0;
    gl.glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
    m_maxPageBytes = static_cast<std::size_t>(std::max(maxTexels, 0)) * kBytesPerTexel;
    gl.glGenBuffers(1, &m_drawNodeBuffer);
    gl.glGenBuffers(1, &m_chunkBuffer);
    gl.glGenTextures(1, &m_pageTexture);
    gl.glGenTextures(1, &m_drawNodeTexture);
    gl.glGenTextures(1, &m_chunkTexture);
}

void ComputeRasterizer::forgetTargets() {
    m_depthImage = m_colorImage = m_clearFramebuffer = 0;
    m_widthPx = m_heightPx = 0;
    m_targetsComplete = false;
}

void ComputeRasterizer::forgetObjects() {
    forgetTargets();
    m_drawNodeBuffer = m_chunkBuffer = 0;
    m_pageTexture = m_drawNodeTexture = m_chunkTexture = 0;
    m_depthProgram.reset();
    m_colorProgram.reset();
    m_resolveProgram.reset();
}

void ComputeRasterizer::releaseTargets(QOpenGLExtraFunctions& gl) {
    if (m_depthImage != 0) {
        gl.glDeleteFramebuffers(1, &m_clearFramebuffer);
        gl.glDeleteTextures(1, &m_depthImage);
        gl.glDeleteTextures(1, &m_colorImage);
    }
    forgetTargets();
}

void ComputeRasterizer::release(QOpenGLExtraFunctions& gl) {
    releaseTargets(gl);
    if (m_drawNodeBuffer != 0) {
        gl.glDeleteBuffers(1, &m_drawNodeBuffer);
        gl.glDeleteBuffers(1, &m_chunkBuffer);
        gl.glDeleteTextures(1, &m_pageTexture);
        gl.glDeleteTextures(1, &m_drawNodeTexture);
        gl.glDeleteTextures(1, &m_chunkTexture);
    }
    forgetObjects();
}

bool ComputeRasterizer::ensureSize(QOpenGLExtraFunctions& gl, int widthPx, int heightPx) {
    if (m_depthImage != 0 && widthPx == m_widthPx && heightPx == m_heightPx) {
        return m_targetsComplete;
    }
    releaseTargets(gl);
    m_widthPx = widthPx;
    m_heightPx = heightPx;
    const auto makeImage = [&](unsigned& texture, GLenum internalFormat) {
        gl.glGenTextures(1, &texture);
        gl.glBindTexture(GL_TEXTURE_2D, texture);
        gl.glTexStorage2D(GL_TEXTURE_2D, 1, internalFormat, widthPx, heightPx);
        gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    };
    makeImage(m_depthImage, GL_R32UI);
    makeImage(m_colorImage, GL_RGBA8);
    gl.glBindTexture(GL_TEXTURE_2D, 0);
    gl.glGenFramebuffers(1, &m_clearFramebuffer);
    gl.glBindFramebuffer(GL_FRAMEBUFFER, m_clearFramebuffer);
    gl.glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, m_depthImage, 0);
    m_targetsComplete = gl.glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    return m_targetsComplete;
}

void ComputeRasterizer::buildTables(const std::vector<Batch>& batches) {
    m_drawNodes.clear();
    m_chunkFirstNode.clear();
    m_dispatches.clear();
    // Nodes grouped by page (stable: the draw order within a page stays).
    m_order.resize(batches.size());
    for (std::size_t i = 0; i < batches.size(); ++i) {
        m_order[i] = i;
    }
    std::stable_sort(m_order.begin(), m_order.end(), [&](std::size_t a, std::size_t b) {
        return batches[a].buffer < batches[b].buffer;
    });
    std::size_t next = 0;
    while (next < m_order.size()) {
        Dispatch dispatch;
        dispatch.buffer = batches[m_order[next]].buffer;
        dispatch.nodeBase = static_cast<std::uint32_t>(m_drawNodes.size());
        dispatch.chunkBase = static_cast<std::uint32_t>(m_chunkFirstNode.size());
        std::uint32_t invocations = 0;
        for (; next < m_order.size() && batches[m_order[next]].buffer == dispatch.buffer; ++next) {
            const Batch& batch = batches[m_order[next]];
            if (batch.pointCount <= 0) {
                continue;
            }
            const auto node = static_cast<std::uint32_t>(m_drawNodes.size()) - dispatch.nodeBase;
            m_drawNodes.push_back({invocations, static_cast<std::uint32_t>(batch.firstPoint),
                                   packColor(batch.levelColor), batch.buildAge});
            const std::uint32_t end = invocations + static_cast<std::uint32_t>(batch.pointCount);
            // Every workgroup that starts inside this node starts its search here.
            for (std::uint32_t chunk = (invocations + kLocalSize - 1) / kLocalSize;
                 chunk * kLocalSize < end; ++chunk) {
                m_chunkFirstNode.push_back(node);
            }
            invocations = end;
        }
        if (invocations == 0) {
            continue;
        }
        m_drawNodes.push_back({invocations, 0, 0, 0.0f}); // sentinel: ends the last node
        dispatch.invocations = invocations;
        m_dispatches.push_back(dispatch);
    }
}

void ComputeRasterizer::uploadTables(QOpenGLExtraFunctions& gl) {
    // Fresh storage each frame (orphaning): the driver need not wait for the last frame. The
    // storage is never smaller than 16 bytes (an empty buffer texture is invalid), so the data
    // goes in separately: handing glBufferData a 4-byte table for 16 bytes would read past it.
    const auto upload = [&](unsigned buffer, const void* data, std::size_t bytes) {
        gl.glBindBuffer(GL_TEXTURE_BUFFER, buffer);
        gl.glBufferData(GL_TEXTURE_BUFFER,
                        static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), nullptr,
                        GL_STREAM_DRAW);
        if (bytes > 0) {
            gl.glBufferSubData(GL_TEXTURE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
        }
    };
    upload(m_drawNodeBuffer, m_drawNodes.data(), m_drawNodes.size() * sizeof(DrawNode));
    upload(m_chunkBuffer, m_chunkFirstNode.data(), m_chunkFirstNode.size() * sizeof(std::uint32_t));
    gl.glBindBuffer(GL_TEXTURE_BUFFER, 0);
    bindBufferTexture(gl, GL_TEXTURE1, m_drawNodeTexture, GL_RGBA32UI, m_drawNodeBuffer);
    bindBufferTexture(gl, GL_TEXTURE2, m_chunkTexture, GL_R32UI, m_chunkBuffer);
}

void ComputeRasterizer::dispatchPass(QOpenGLExtraFunctions& gl, QOpenGLShaderProgram& program) {
    program.setUniformValue("u_pagePoints", 0);
    program.setUniformValue("u_drawNodes", 1);
    program.setUniformValue("u_chunkNodes", 2);
    const int countLocation = program.uniformLocation("u_pointCount");
    const int nodeBaseLocation = program.uniformLocation("u_nodeBase");
    const int chunkBaseLocation = program.uniformLocation("u_chunkBase");
    for (const Dispatch& dispatch : m_dispatches) {
        gl.glUniform1ui(countLocation, dispatch.invocations);
        gl.glUniform1ui(nodeBaseLocation, dispatch.nodeBase);
        gl.glUniform1ui(chunkBaseLocation, dispatch.chunkBase);
        bindBufferTexture(gl, GL_TEXTURE0, m_pageTexture, GL_RGBA32UI, dispatch.buffer);
        const GLuint groups = (dispatch.invocations + kLocalSize - 1) / kLocalSize;
        const GLuint groupsX = std::min(groups, kMaxGroupsPerDimension);
        const GLuint groupsY = (groups + groupsX - 1) / groupsX;
        gl.glDispatchCompute(groupsX, groupsY, 1);
    }
}

bool ComputeRasterizer::draw(QOpenGLExtraFunctions& gl, unsigned targetFramebuffer, int widthPx,
                             int heightPx, const std::vector<Batch>& batches,
                             const std::function<void(QOpenGLShaderProgram&)>& setUniforms) {
    if (!available() || !ensureSize(gl, widthPx, heightPx)) {
        return false;
    }
    // Pass 0: every pixel empty.
    gl.glBindFramebuffer(GL_FRAMEBUFFER, m_clearFramebuffer);
    gl.glViewport(0, 0, widthPx, heightPx);
    const GLuint empty[4] = {kEmptyDepth, kEmptyDepth, kEmptyDepth, kEmptyDepth};
    gl.glClearBufferuiv(GL_COLOR, 0, empty);

    buildTables(batches);
    uploadTables(gl);
    gl.glBindImageTexture(kDepthImageUnit, m_depthImage, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    gl.glBindImageTexture(kColorImageUnit, m_colorImage, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
    for (QOpenGLShaderProgram* program : {m_depthProgram.get(), m_colorProgram.get()}) {
        program->bind();
        setUniforms(*program);
        gl.glUniform2i(program->uniformLocation("u_viewportPx"), widthPx, heightPx);
        dispatchPass(gl, *program);
        // Pass 2 reads every depth of pass 1; the resolve fetches both images.
        gl.glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }

    // Pass 3: resolve into the frame.
    gl.glBindFramebuffer(GL_FRAMEBUFFER, targetFramebuffer);
    gl.glViewport(0, 0, widthPx, heightPx);
    gl.glEnable(GL_DEPTH_TEST);
    gl.glDepthFunc(GL_LESS); // against what is already in the frame
    gl.glDepthMask(GL_TRUE);
    m_resolveProgram->bind();
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindTexture(GL_TEXTURE_2D, m_depthImage);
    gl.glActiveTexture(GL_TEXTURE1);
    gl.glBindTexture(GL_TEXTURE_2D, m_colorImage);
    m_resolveProgram->setUniformValue("u_depth", 0);
    m_resolveProgram->setUniformValue("u_color", 1);
    gl.glDrawArrays(GL_TRIANGLES, 0, 3);
    m_resolveProgram->release();

    gl.glBindTexture(GL_TEXTURE_2D, 0);
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindTexture(GL_TEXTURE_2D, 0);
    for (GLenum unit : {GL_TEXTURE0, GL_TEXTURE1, GL_TEXTURE2}) {
        gl.glActiveTexture(unit);
        gl.glBindTexture(GL_TEXTURE_BUFFER, 0);
    }
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindImageTexture(kDepthImageUnit, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    gl.glBindImageTexture(kColorImageUnit, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
    return true;
}

} // namespace omicron
