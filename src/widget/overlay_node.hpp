// Line overlays drawn after the cloud: the cloud's bounding box, the cells of the front's
// nodes (coloured by level; optional) and the oblique cut's boundary — the leaves the builder
// has inserted that are not settled yet, where the sweep is working now — and the cell of a
// highlighted node (CloudView::setHighlightedNode), drawn over the points.
#pragma once

#include "scene_node.hpp"

#include <QOpenGLShaderProgram>
#include <glm/vec3.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace omicron {

class CloudNode;

class OverlayNode final : public SceneNode {
public:
    explicit OverlayNode(const CloudNode& cloud) : m_cloud(cloud) {}

    void initializeGL(QOpenGLExtraFunctions& gl) override;
    void render(RenderContext& context) override;
    void releaseGL(QOpenGLExtraFunctions& gl) override;

    // The node whose cell is drawn as a box (a Morton code with its sentinel bit), or none.
    void setHighlight(std::optional<std::uint64_t> code) { m_highlight = code; }
    std::optional<std::uint64_t> highlight() const { return m_highlight; }
    // Measurement polylines in the unit cube (closed ones end at their first point), drawn
    // over the points like the highlight, with a cross at each vertex.
    void setMeasurementLines(std::vector<std::vector<glm::dvec3>> polylines) {
        m_measurements = std::move(polylines);
    }

    struct LineVertex {
        float x, y, z;
        std::uint8_t r, g, b, a;
    };

private:
    void addBox(const glm::dvec3& min, const glm::dvec3& max, const std::uint8_t (&rgba)[4]);

    const CloudNode& m_cloud;
    std::optional<std::uint64_t> m_highlight;
    std::vector<std::vector<glm::dvec3>> m_measurements;
    std::vector<LineVertex> m_lines;
    std::unique_ptr<QOpenGLShaderProgram> m_program;
    unsigned m_vao = 0;
    unsigned m_vbo = 0;
};

// Cell of a Morton code in the unit cube.
void cellBounds(std::uint64_t code, glm::dvec3& min, glm::dvec3& max);

} // namespace omicron
