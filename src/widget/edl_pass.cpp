#include "edl_pass.hpp"

#include "gl_texture.hpp"
#include "shader_library.hpp"

namespace omicron {

void EdlPass::initializeGL() {
    m_program = buildShaderProgram({"fullscreen.vert", "edl.frag"});
}

void EdlPass::releaseGL(QOpenGLExtraFunctions& gl) {
    if (m_framebuffer != 0) {
        gl.glDeleteFramebuffers(1, &m_framebuffer);
        gl.glDeleteTextures(1, &m_color);
        gl.glDeleteTextures(1, &m_depth);
    }
    if (m_vao != 0) {
        gl.glDeleteVertexArrays(1, &m_vao);
    }
    m_framebuffer = m_color = m_depth = m_vao = 0;
    m_widthPx = m_heightPx = 0;
    m_complete = false;
    m_program.reset();
}

bool EdlPass::begin(QOpenGLExtraFunctions& gl, int widthPx, int heightPx,
                    const float background[3]) {
    if (m_framebuffer == 0 || widthPx != m_widthPx || heightPx != m_heightPx) {
        if (m_framebuffer != 0) {
            gl.glDeleteFramebuffers(1, &m_framebuffer);
            gl.glDeleteTextures(1, &m_color);
            gl.glDeleteTextures(1, &m_depth);
        }
        m_widthPx = widthPx;
        m_heightPx = heightPx;
        makeTargetTexture(gl, m_color, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, widthPx, heightPx);
        makeTargetTexture(gl, m_depth, GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT,
                    widthPx, heightPx);
        gl.glBindTexture(GL_TEXTURE_2D, 0);
        gl.glGenFramebuffers(1, &m_framebuffer);
        gl.glBindFramebuffer(GL_FRAMEBUFFER, m_framebuffer);
        gl.glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, m_color, 0);
        gl.glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, m_depth, 0);
        m_complete = gl.glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    if (!m_complete) {
        return false;
    }
    gl.glBindFramebuffer(GL_FRAMEBUFFER, m_framebuffer);
    gl.glViewport(0, 0, widthPx, heightPx);
    gl.glClearColor(background[0], background[1], background[2], 0.0f); // alpha 0: nothing drawn
    gl.glClearDepthf(1.0f);
    gl.glDepthMask(GL_TRUE);
    gl.glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    return true;
}

void EdlPass::composite(QOpenGLExtraFunctions& gl, unsigned framebuffer,
                        const glm::dmat4& projection, bool orthographic, float strength,
                        float radiusPx) {
    gl.glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl.glViewport(0, 0, m_widthPx, m_heightPx);
    if (m_vao == 0) {
        gl.glGenVertexArrays(1, &m_vao); // core profile: a draw needs one, even without buffers
    }
    gl.glBindVertexArray(m_vao);
    gl.glEnable(GL_DEPTH_TEST);
    gl.glDepthFunc(GL_ALWAYS);
    gl.glDepthMask(GL_TRUE);
    gl.glDisable(GL_BLEND);
    m_program->bind();
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindTexture(GL_TEXTURE_2D, m_color);
    gl.glActiveTexture(GL_TEXTURE1);
    gl.glBindTexture(GL_TEXTURE_2D, m_depth);
    m_program->setUniformValue("u_color", 0);
    m_program->setUniformValue("u_depth", 1);
    m_program->setUniformValue("u_pixel", 1.0f / static_cast<float>(m_widthPx),
                               1.0f / static_cast<float>(m_heightPx));
    m_program->setUniformValue("u_radius", radiusPx);
    m_program->setUniformValue("u_strength", strength);
    m_program->setUniformValue("u_p22", static_cast<float>(projection[2][2]));
    m_program->setUniformValue("u_p32", static_cast<float>(projection[3][2]));
    m_program->setUniformValue("u_orthographic", orthographic);
    gl.glDrawArrays(GL_TRIANGLES, 0, 3);
    m_program->release();
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindTexture(GL_TEXTURE_2D, 0);
    gl.glDepthFunc(GL_LESS);
    gl.glBindVertexArray(0);
}

} // namespace omicron
