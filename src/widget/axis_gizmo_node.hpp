// The axis gizmo: x (red), y (green) and z (blue) of the cloud's frame, turning with the
// camera, in a small viewport in the lower-left corner.
#pragma once

#include "scene_node.hpp"

#include <QOpenGLShaderProgram>
#include <memory>

namespace omicron {

class AxisGizmoNode final : public SceneNode {
public:
    static constexpr int kSizePx = 90;

    void initializeGL(QOpenGLExtraFunctions& gl) override;
    void render(RenderContext& context) override;
    void releaseGL(QOpenGLExtraFunctions& gl) override;

private:
    std::unique_ptr<QOpenGLShaderProgram> m_program;
    unsigned m_vao = 0;
    unsigned m_vbo = 0;
};

} // namespace omicron
