#include "axis_gizmo_node.hpp"

#include "shader_library.hpp"

#include <algorithm>
#include <cstdint>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace omicron {

namespace {

struct GizmoVertex {
    float x, y, z;
    std::uint8_t r, g, b, a;
};

constexpr GizmoVertex kAxes[6] = {
    {0, 0, 0, 230, 60, 60, 255}, {1, 0, 0, 230, 60, 60, 255},
    {0, 0, 0, 80, 200, 80, 255}, {0, 1, 0, 80, 200, 80, 255},
    {0, 0, 0, 80, 130, 255, 255}, {0, 0, 1, 80, 130, 255, 255},
};

} // namespace

void AxisGizmoNode::initializeGL(QOpenGLExtraFunctions& gl) {
    m_program = buildShaderProgram({"lines.vert", "lines.frag"});
    gl.glGenVertexArrays(1, &m_vao);
    gl.glGenBuffers(1, &m_vbo);
    gl.glBindVertexArray(m_vao);
    gl.glBindBuffer(GL_ARRAY_BUFFER, m_vbo);
    gl.glBufferData(GL_ARRAY_BUFFER, sizeof(kAxes), kAxes, GL_STATIC_DRAW);
    const auto stride = static_cast<GLsizei>(sizeof(GizmoVertex));
    gl.glEnableVertexAttribArray(0);
    gl.glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
    gl.glEnableVertexAttribArray(1);
    gl.glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride, reinterpret_cast<void*>(12));
    gl.glBindVertexArray(0);
    gl.glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void AxisGizmoNode::releaseGL(QOpenGLExtraFunctions& gl) {
    if (m_vao != 0) {
        gl.glDeleteVertexArrays(1, &m_vao);
        gl.glDeleteBuffers(1, &m_vbo);
    }
    m_vao = m_vbo = 0;
    m_program.reset();
}

void AxisGizmoNode::render(RenderContext& context) {
    if (!context.settings->showAxes) {
        return;
    }
    QOpenGLExtraFunctions& gl = *context.gl;
    const int sizePx = std::min({kSizePx, context.widthPx, context.heightPx});
    // The camera's rotation only, looking at the origin from a fixed distance.
    glm::dmat4 rotation = context.view;
    rotation[3] = glm::dvec4(0.0, 0.0, -3.0, 1.0);
    const glm::dmat4 projection = glm::ortho(-1.3, 1.3, -1.3, 1.3, 0.1, 10.0);
    const glm::mat4 viewProjection(projection * rotation);

    gl.glBindFramebuffer(GL_FRAMEBUFFER, context.targetFramebuffer);
    gl.glViewport(0, 0, sizePx, sizePx);
    gl.glDisable(GL_DEPTH_TEST);
    m_program->bind();
    m_program->setUniformValue("u_viewProjection",
                               QMatrix4x4(glm::value_ptr(viewProjection)).transposed());
    gl.glBindVertexArray(m_vao);
    gl.glDrawArrays(GL_LINES, 0, 6);
    gl.glBindVertexArray(0);
    m_program->release();
    gl.glViewport(0, 0, context.widthPx, context.heightPx);
    gl.glEnable(GL_DEPTH_TEST);
}

} // namespace omicron
