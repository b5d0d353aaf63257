#include "overlay_node.hpp"

#include "cloud_node.hpp"
#include "shader_library.hpp"

#include <glm/gtc/type_ptr.hpp>

namespace omicron {

namespace {

// Enough cells to show the structure; beyond this the overlay only costs frame time.
constexpr std::size_t kMaxCellsDrawn = 20000;

constexpr std::uint8_t kBoxColor[4] = {200, 200, 200, 255};
constexpr std::uint8_t kCutColor[4] = {255, 140, 0, 255};
// The highlighted node: magenta, a colour no other overlay and no colour mode's ramp uses.
constexpr std::uint8_t kHighlightColor[4] = {255, 0, 255, 255};
constexpr std::uint8_t kMeasureColor[4] = {255, 220, 40, 255};

} // namespace

void cellBounds(std::uint64_t code, glm::dvec3& min, glm::dvec3& max) {
    const morton::Cell cell = morton::decode(code);
    const double size = 1.0 / static_cast<double>(std::uint64_t{1} << morton::level(code));
    min = glm::dvec3(cell.x, cell.y, cell.z) * size;
    max = min + glm::dvec3(size);
}

void OverlayNode::initializeGL(QOpenGLExtraFunctions& gl) {
    m_program = buildShaderProgram({"lines.vert", "lines.frag"});
    gl.glGenVertexArrays(1, &m_vao);
    gl.glGenBuffers(1, &m_vbo);
}

void OverlayNode::releaseGL(QOpenGLExtraFunctions& gl) {
    if (m_vao != 0) {
        gl.glDeleteVertexArrays(1, &m_vao);
        gl.glDeleteBuffers(1, &m_vbo);
    }
    m_vao = m_vbo = 0;
    m_program.reset();
}

void OverlayNode::addBox(const glm::dvec3& min, const glm::dvec3& max,
                         const std::uint8_t (&rgba)[4]) {
    const auto corner = [&](int i) {
        return glm::vec3(i & 1 ? max.x : min.x, i & 2 ? max.y : min.y, i & 4 ? max.z : min.z);
    };
    static constexpr int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                          {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    for (const auto& edge : kEdges) {
        for (int end : edge) {
            const glm::vec3 p = corner(end);
            m_lines.push_back({p.x, p.y, p.z, rgba[0], rgba[1], rgba[2], rgba[3]});
        }
    }
}

void OverlayNode::render(RenderContext& context) {
    const RenderSettings& settings = *context.settings;
    m_lines.clear();
    if (settings.showBoundingBox && m_cloud.hasBounds()) {
        addBox(m_cloud.boundsMin(), m_cloud.boundsMax(), kBoxColor);
    }
    if (const Front* front = m_cloud.front(); front != nullptr) {
        std::size_t cells = 0;
        for (const FrontEntry& entry : front->entries()) {
            if (cells >= kMaxCellsDrawn) {
                break;
            }
            glm::dvec3 min, max;
            if (entry.placeholder && settings.showCutBoundary) {
                cellBounds(entry.code, min, max);
                addBox(min, max, kCutColor);
                ++cells;
            } else if (!entry.placeholder && entry.visible && settings.showOctreeCells) {
                cellBounds(entry.code, min, max);
                const float shade = 0.35f + 0.65f * static_cast<float>(entry.level()) / morton::kMaxLevel;
                const auto channel = static_cast<std::uint8_t>(255.0f * shade);
                const std::uint8_t rgba[4] = {60, channel, 255, 160};
                addBox(min, max, rgba);
                ++cells;
            }
        }
    }
    // The highlight goes last and is drawn without the depth test: a selected node stays
    // visible inside or behind the cloud. Two boxes, the second 1 % larger, for a bolder line
    // (core profiles have no wide lines).
    const std::size_t highlightBegin = m_lines.size();
    if (m_highlight && morton::isValid(*m_highlight) &&
        morton::level(*m_highlight) <= morton::kMaxLevel) {
        glm::dvec3 min, max;
        cellBounds(*m_highlight, min, max);
        addBox(min, max, kHighlightColor);
        const glm::dvec3 grow = (max - min) * 0.005;
        addBox(min - grow, max + grow, kHighlightColor);
    }
    for (const std::vector<glm::dvec3>& polyline : m_measurements) {
        const auto vertex = [&](const glm::dvec3& p) {
            m_lines.push_back({static_cast<float>(p.x), static_cast<float>(p.y),
                               static_cast<float>(p.z), kMeasureColor[0], kMeasureColor[1],
                               kMeasureColor[2], kMeasureColor[3]});
        };
        for (std::size_t i = 1; i < polyline.size(); ++i) {
            vertex(polyline[i - 1]);
            vertex(polyline[i]);
        }
        // A cross at each picked point, a few thousandths of the cube across.
        constexpr double kCross = 0.004;
        for (const glm::dvec3& p : polyline) {
            for (int axis = 0; axis < 3; ++axis) {
                glm::dvec3 step(0.0);
                step[axis] = kCross;
                vertex(p - step);
                vertex(p + step);
            }
        }
    }
    if (m_lines.empty()) {
        return;
    }
    QOpenGLExtraFunctions& gl = *context.gl;
    gl.glBindFramebuffer(GL_FRAMEBUFFER, context.targetFramebuffer);
    gl.glBindVertexArray(m_vao);
    gl.glBindBuffer(GL_ARRAY_BUFFER, m_vbo);
    gl.glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(m_lines.size() * sizeof(LineVertex)),
                    m_lines.data(), GL_STREAM_DRAW);
    const auto stride = static_cast<GLsizei>(sizeof(LineVertex));
    gl.glEnableVertexAttribArray(0);
    gl.glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
    gl.glEnableVertexAttribArray(1);
    gl.glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride, reinterpret_cast<void*>(12));
    gl.glEnable(GL_DEPTH_TEST);
    gl.glDepthFunc(GL_LEQUAL);
    gl.glEnable(GL_BLEND);
    gl.glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    m_program->bind();
    const glm::mat4 viewProjection(context.projection * context.view);
    m_program->setUniformValue("u_viewProjection",
                               QMatrix4x4(glm::value_ptr(viewProjection)).transposed());
    gl.glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(highlightBegin));
    if (highlightBegin < m_lines.size()) {
        gl.glDisable(GL_DEPTH_TEST);
        gl.glDrawArrays(GL_LINES, static_cast<GLint>(highlightBegin),
                        static_cast<GLsizei>(m_lines.size() - highlightBegin));
        gl.glEnable(GL_DEPTH_TEST);
    }
    m_program->release();
    gl.glDisable(GL_BLEND);
    gl.glDepthFunc(GL_LESS);
    gl.glBindBuffer(GL_ARRAY_BUFFER, 0);
    gl.glBindVertexArray(0);
}

} // namespace omicron
