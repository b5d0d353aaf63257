// The scene node that draws the cloud: a Front over the attached hierarchy (or the sorter's
// preview before anything is renderable), node buffers uploaded within the per-frame budget,
// and the points, compute-points or surface-splat passes.
#pragma once

#include "compute_rasterizer.hpp"
#include "first_draw_tracker.hpp"
#include "front/front.hpp"
#include "node_buffer_cache.hpp"
#include "node_vertices.hpp"
#include "scene_node.hpp"
#include "splat_target.hpp"

#include <QOpenGLShaderProgram>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <vector>

namespace omicron {

class Hierarchy;
class ViewCamera;

class CloudNode final : public SceneNode {
public:
    CloudNode();
    ~CloudNode() override;

    void setHierarchy(std::shared_ptr<const Hierarchy> hierarchy);
    const std::shared_ptr<const Hierarchy>& hierarchy() const { return m_hierarchy; }
    void setPreview(std::vector<PointVertex> vertices);
    bool hasPreview() const { return !m_previewVertices.empty() || m_previewVbo != 0; }

    // Bounds (unit cube) of the points seen so far: the cloud's published points, else the
    // preview; empty (min > max) before any. A cloud paged in on demand publishes no prefix:
    // its bounds are the cells of the deepest level loaded so far.
    glm::dvec3 boundsMin() const { return m_boundsMin; }
    glm::dvec3 boundsMax() const { return m_boundsMax; }
    bool hasBounds() const { return m_boundsMin.x <= m_boundsMax.x; }
    // Grows the bounds over the cloud's newly published points (bounded work per call).
    void updateBounds(std::size_t maxPoints);
    bool boundsPending() const;

    // The front of the last frame (empty without a hierarchy).
    const Front* front() const { return m_front.get(); }
    // Leaves first drawn since the last call and their publish -> drawn delays (all the
    // render() calls of one frame: a screenshot renders twice).
    FirstDrawTracker::Delays takeFirstDraws() { return m_firstDraws.take(); }

    // Whether the cloud has colours of its own (unknown before a hierarchy: false), for
    // EdlMode::Auto.
    bool hasColor() const;

    // Whether RenderMode::ComputePoints runs the compute rasterizer in this context (else it
    // draws GL points).
    bool computePointsAvailable() const { return m_compute.available(); }

    void initializeGL(QOpenGLExtraFunctions& gl) override;
    void render(RenderContext& context) override;
    void releaseGL(QOpenGLExtraFunctions& gl) override;

private:
    struct DrawItem {
        NodeBufferCache::Key key;
        int level;
        std::uint32_t index;
        float buildAge;
        // Resident buffer, nullptr until uploaded (cache entries do not move before eviction,
        // which runs after drawing).
        const NodeBufferCache::Buffer* buffer;
    };

    const OctreeNode& nodeOf(const DrawItem& item) const;
    void evaluateFront(RenderContext& context);
    void collectDrawList(RenderContext& context);
    void uploadPreview(QOpenGLExtraFunctions& gl);
    void setCommonUniforms(QOpenGLShaderProgram& program, const RenderContext& context,
                           float depthOffset);
    void bindVertexLayout(QOpenGLExtraFunctions& gl, unsigned vbo);
    void drawItems(RenderContext& context, QOpenGLShaderProgram& program);
    void drawPreview(RenderContext& context);
    void drawPoints(RenderContext& context);
    void drawSplats(RenderContext& context);
    void drawComputePoints(RenderContext& context);
    void recordFirstDraws();
    void updatePagedBounds();
    int effectiveColorMode(const RenderSettings& settings) const;

    std::shared_ptr<const Hierarchy> m_hierarchy;
    std::unique_ptr<Front> m_front;
    NodeBufferCache m_cache;
    // Vertices of the nodes uploaded next, packed in parallel.
    std::vector<const OctreeNode*> m_packNodes;
    std::vector<std::vector<PointVertex>> m_packed;
    std::vector<DrawItem> m_drawList;
    FirstDrawTracker m_firstDraws;
    std::vector<FirstDrawTracker::CoveredRange> m_drawnRanges;
    std::uint64_t m_frame = 0;
    bool m_hierarchyChanged = false;

    std::vector<PointVertex> m_previewVertices; // waiting for upload
    unsigned m_previewVbo = 0;
    int m_previewCount = 0;

    // GPS times are uploaded relative to a base taken from the first node packed, and the
    // range of those packed so far scales the GPS-time colour ramp.
    std::optional<double> m_gpsTimeBase;
    ValueRange m_gpsTimes;

    std::size_t m_boundsScanned = 0;
    int m_boundsLevel = -1; // paged: the level whose cells the bounds are
    glm::dvec3 m_boundsMin{1.0};
    glm::dvec3 m_boundsMax{0.0};

    bool m_initialized = false;
    unsigned m_vao = 0;
    std::unique_ptr<QOpenGLShaderProgram> m_pointsProgram;
    std::unique_ptr<QOpenGLShaderProgram> m_visibilityProgram;
    std::unique_ptr<QOpenGLShaderProgram> m_accumulateProgram;
    std::unique_ptr<QOpenGLShaderProgram> m_normalizeProgram;
    SplatTarget m_splatTarget;
    ComputeRasterizer m_compute;
    std::vector<ComputeRasterizer::Batch> m_computeBatches;
};

} // namespace omicron
