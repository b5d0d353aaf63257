// The viewer's small scene graph (no OpenSceneGraph): a root that draws its nodes in order.
// Each node owns its GL resources: it creates them in initializeGL() and frees them in
// releaseGL(), which CloudView calls when its context is about to be destroyed (not from a
// destructor, where no context may be current).
#pragma once

#include "render_settings.hpp"

#include <QOpenGLExtraFunctions>
#include <glm/mat4x4.hpp>
#include <memory>
#include <vector>

namespace omicron {

class ViewCamera;

// What a node needs to draw one frame.
struct RenderContext {
    QOpenGLExtraFunctions* gl = nullptr;
    const ViewCamera* camera = nullptr;
    const RenderSettings* settings = nullptr;
    glm::dmat4 view{1.0};
    glm::dmat4 projection{1.0};
    int widthPx = 1; // device pixels
    int heightPx = 1;
    unsigned targetFramebuffer = 0; // where the frame goes (the widget's FBO)
    bool settle = false; // render to completion: whole front, no upload budget (screenshots)
    FrameStats* stats = nullptr;
};

class SceneNode {
public:
    virtual ~SceneNode() = default;
    virtual void initializeGL(QOpenGLExtraFunctions& gl) = 0;
    virtual void render(RenderContext& context) = 0;
    virtual void releaseGL(QOpenGLExtraFunctions& gl) = 0;
};

class SceneGraph {
public:
    // Takes ownership; nodes draw in insertion order. Returns the node for the caller's use.
    template <typename Node> Node* add(std::unique_ptr<Node> node) {
        Node* raw = node.get();
        m_nodes.push_back(std::move(node));
        return raw;
    }
    void initializeGL(QOpenGLExtraFunctions& gl) {
        for (auto& node : m_nodes) {
            node->initializeGL(gl);
        }
    }
    void render(RenderContext& context) { render(context, 0, m_nodes.size()); }
    // Nodes [first, end) only: a pass such as eye-dome lighting between them.
    void render(RenderContext& context, std::size_t first, std::size_t end) {
        for (std::size_t i = first; i < end && i < m_nodes.size(); ++i) {
            m_nodes[i]->render(context);
        }
    }
    std::size_t size() const { return m_nodes.size(); }
    void releaseGL(QOpenGLExtraFunctions& gl) {
        for (auto& node : m_nodes) {
            node->releaseGL(gl);
        }
    }

private:
    std::vector<std::unique_ptr<SceneNode>> m_nodes;
};

} // namespace omicron
