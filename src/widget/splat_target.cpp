#include "splat_target.hpp"

#include "gl_texture.hpp"

namespace omicron {

bool SplatTarget::ensureSize(QOpenGLExtraFunctions& gl, int widthPx, int heightPx) {
    if (m_framebuffer != 0 && widthPx == m_widthPx && heightPx == m_heightPx) {
        return m_complete;
    }
    release(gl);
    m_widthPx = widthPx;
    m_heightPx = heightPx;
    makeTargetTexture(gl, m_accumulation, GL_RGBA16F, GL_RGBA, GL_FLOAT, widthPx, heightPx);
    makeTargetTexture(gl, m_depth, GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, widthPx,
                heightPx);
    gl.glBindTexture(GL_TEXTURE_2D, 0);
    gl.glGenFramebuffers(1, &m_framebuffer);
    gl.glBindFramebuffer(GL_FRAMEBUFFER, m_framebuffer);
    gl.glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, m_accumulation, 0);
    gl.glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, m_depth, 0);
    m_complete = gl.glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    return m_complete;
}

void SplatTarget::release(QOpenGLExtraFunctions& gl) {
    if (m_framebuffer != 0) {
        gl.glDeleteFramebuffers(1, &m_framebuffer);
        gl.glDeleteTextures(1, &m_accumulation);
        gl.glDeleteTextures(1, &m_depth);
    }
    m_framebuffer = m_accumulation = m_depth = 0;
    m_widthPx = m_heightPx = 0;
    m_complete = false;
}

} // namespace omicron
