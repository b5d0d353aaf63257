// Eye-dome lighting: the cloud is drawn into an offscreen colour + depth target, then one
// full-screen pass (shaders/edl.frag) writes it into the frame darkened where neighbouring
// pixels lie in front — the depth cue that makes an uncoloured lidar tile readable. Works
// for every render mode, since each writes the depth of what it drew.
#pragma once

#include <QOpenGLExtraFunctions>
#include <QOpenGLShaderProgram>
#include <glm/mat4x4.hpp>
#include <memory>

namespace omicron {

class EdlPass {
public:
    void initializeGL();
    void releaseGL(QOpenGLExtraFunctions& gl);

    // Binds the offscreen target (sized to the frame) cleared to `background`; false when
    // the driver cannot make one (the frame is then drawn without EDL).
    bool begin(QOpenGLExtraFunctions& gl, int widthPx, int heightPx, const float background[3]);
    unsigned framebuffer() const { return m_framebuffer; }

    // Draws the target into `framebuffer` with the shading; `projection` is the frame's, for
    // the linear depth.
    void composite(QOpenGLExtraFunctions& gl, unsigned framebuffer, const glm::dmat4& projection,
                   bool orthographic, float strength, float radiusPx);

private:
    std::unique_ptr<QOpenGLShaderProgram> m_program;
    unsigned m_framebuffer = 0;
    unsigned m_color = 0;
    unsigned m_depth = 0;
    unsigned m_vao = 0;
    int m_widthPx = 0;
    int m_heightPx = 0;
    bool m_complete = false;
};

} // namespace omicron
