#include "cloud_node.hpp"

#include "build/hierarchy.hpp"
#include "front/front_projection.hpp"
#include "front/front_settle.hpp"
#include "points/asprs_classes.hpp"
#include "shader_library.hpp"
#include "view_camera.hpp"

#include <QElapsedTimer>
#include <QOpenGLContext>
#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>

namespace omicron {

namespace {

// Screen-size limits of one point: at least a pixel, at most what every driver supports.
constexpr float kMinPointPx = 1.0f;
constexpr float kMaxPointPx = 64.0f;
// Splat visibility pass: splats pushed back by this many radii so that overlapping splats of
// one surface pass the depth test of the accumulation pass and blend.
constexpr float kSplatDepthOffsetRadii = 1.0f;
// Nodes packed per parallel batch: bounds the memory of packed vertices waiting for upload.
constexpr std::size_t kPackBatchBytes = std::size_t{8} << 20;
// Screenshots: most front evaluations spent converging before the image is taken.
constexpr int kMaxSettleEvaluations = 256;
// Screenshots of a hierarchy paged in on demand: the most time spent waiting for loads.
constexpr double kMaxPagedSettleSeconds = 120.0;

glm::vec3 levelColor(int level) {
    // Hues spaced by the golden angle: neighbouring levels never look alike.
    const float hue = std::fmod(static_cast<float>(level) * 0.618034f + 0.1f, 1.0f) * 6.0f;
    const float x = 1.0f - std::fabs(std::fmod(hue, 2.0f) - 1.0f);
    const int sector = static_cast<int>(hue);
    const glm::vec3 table[6] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
    return glm::vec3(0.25f) + table[std::clamp(sector, 0, 5)] * 0.75f;
}

// lasClassColor of every class, RGBA8 with red lowest, for color.glsl's u_classColors.
const std::array<std::uint32_t, kLasClassCount>& classPalette() {
    static const std::array<std::uint32_t, kLasClassCount> palette = [] {
        std::array<std::uint32_t, kLasClassCount> packed{};
        for (int c = 0; c < kLasClassCount; ++c) {
            const glm::u8vec3 color = lasClassColor(c);
            packed[static_cast<std::size_t>(c)] = std::uint32_t{color.r} |
                                                  (std::uint32_t{color.g} << 8) |
                                                  (std::uint32_t{color.b} << 16) | (255u << 24);
        }
        return packed;
    }();
    return palette;
}

// The hidden classes as color.glsl's u_hiddenClasses: class c is bit c % 32 of word c / 32.
std::array<std::uint32_t, kLasClassCount / 32>
hiddenClassWords(const std::bitset<kLasClassCount>& hidden) {
    std::array<std::uint32_t, kLasClassCount / 32> words{};
    for (std::size_t c = 0; c < hidden.size(); ++c) {
        if (hidden.test(c)) {
            words[c / 32] |= 1u << (c % 32);
        }
    }
    return words;
}

} // namespace

CloudNode::CloudNode() = default;
CloudNode::~CloudNode() = default;

void CloudNode::setHierarchy(std::shared_ptr<const Hierarchy> hierarchy) {
    m_hierarchy = std::move(hierarchy);
    m_front = m_hierarchy ? std::make_unique<Front>(m_hierarchy) : nullptr;
    m_firstDraws.reset(FirstDrawTracker::Clock::now());
    m_hierarchyChanged = true;
    m_drawList.clear();
    m_boundsScanned = 0;
    m_boundsLevel = -1;
    m_boundsMin = glm::dvec3(1.0);
    m_boundsMax = glm::dvec3(0.0);
    m_gpsTimeBase.reset();
    m_gpsTimes = ValueRange{};
}

void CloudNode::setPreview(std::vector<PointVertex> vertices) {
    m_previewVertices = std::move(vertices);
    if (m_previewVertices.empty()) {
        m_previewCount = 0;
    }
    if (!m_hierarchy || m_boundsScanned == 0) {
        for (const PointVertex& v : m_previewVertices) {
            m_boundsMin = glm::min(m_boundsMin, glm::dvec3(v.x, v.y, v.z));
            m_boundsMax = glm::max(m_boundsMax, glm::dvec3(v.x, v.y, v.z));
        }
    }
}

void CloudNode::updateBounds(std::size_t maxPoints) {
    if (!m_hierarchy) {
        return;
    }
    const SortedCloud& cloud = m_hierarchy->cloud();
    if (cloud.pagedOnDemand()) {
        updatePagedBounds();
        return;
    }
    const std::size_t published = cloud.sortedEnd();
    if (m_boundsScanned == 0 && published > 0) {
        // The preview's bounds were provisional; the cloud's own points replace them.
        m_boundsMin = glm::dvec3(1.0);
        m_boundsMax = glm::dvec3(0.0);
    }
    const std::size_t end = std::min(published, m_boundsScanned + maxPoints);
    glm::vec3 low(m_boundsMin), high(m_boundsMax);
    cloud.visitPositions([&](const auto& positions) {
        for (std::size_t i = m_boundsScanned; i < end; ++i) {
            const glm::vec3 p = positions[i];
            low = glm::min(low, p);
            high = glm::max(high, p);
        }
    });
    m_boundsMin = glm::dvec3(low);
    m_boundsMax = glm::dvec3(high);
    m_boundsScanned = end;
}

void CloudNode::updatePagedBounds() {
    // Its points are read only as the front asks for them, so the nodes stand for them: the
    // deepest level loaded so far, whose cells hug the points within a cell's edge (1/128 of
    // the cube at level 7). Node records arrive level by level in a few milliseconds.
    int deepest = -1;
    for (int level = 0; level <= m_hierarchy->maxLevel(); ++level) {
        if (m_hierarchy->nodeCount(level) > 0) {
            deepest = level;
        }
    }
    if (deepest <= m_boundsLevel) {
        return;
    }
    glm::dvec3 low(1.0), high(0.0);
    for (std::size_t i = 0; i < m_hierarchy->nodeCount(deepest); ++i) {
        const CellBox box = cellBox(m_hierarchy->node(deepest, i).code);
        low = glm::min(low, box.min);
        high = glm::max(high, box.min + glm::dvec3(box.edge));
    }
    m_boundsMin = low;
    m_boundsMax = high;
    m_boundsLevel = deepest;
}

bool CloudNode::boundsPending() const {
    return m_hierarchy && m_boundsScanned < m_hierarchy->cloud().sortedEnd();
}

void CloudNode::initializeGL(QOpenGLExtraFunctions& gl) {
    m_pointsProgram = buildShaderProgram({"points.vert", "points.frag", {"color.glsl"}});
    m_visibilityProgram = buildShaderProgram(
        {"points.vert", "splat_visibility.frag", {"color.glsl"}, {"splat_disc.glsl"}});
    m_accumulateProgram = buildShaderProgram(
        {"points.vert", "splat_accumulate.frag", {"color.glsl"}, {"splat_disc.glsl"}});
    m_normalizeProgram = buildShaderProgram({"fullscreen.vert", "splat_normalize.frag"});
    gl.glGenVertexArrays(1, &m_vao);
    if (QOpenGLContext* context = QOpenGLContext::currentContext()) {
        m_compute.initializeGL(*context);
    }
    m_initialized = true;
    // A new context: every buffer has to be uploaded again.
    m_cache.abandon();
    if (m_compute.available()) {
        // The compute rasterizer reads a whole page through one buffer texture.
        m_cache.setPagePoints(std::min(NodeBufferCache::kDefaultPagePoints,
                                       m_compute.maxPageBytes() / sizeof(PointVertex)));
    }
    m_previewVbo = 0;
}

void CloudNode::releaseGL(QOpenGLExtraFunctions& gl) {
    if (!m_initialized) {
        return;
    }
    m_cache.clear(gl);
    if (m_previewVbo != 0) {
        gl.glDeleteBuffers(1, &m_previewVbo);
        m_previewVbo = 0;
    }
    m_splatTarget.release(gl);
    m_compute.release(gl);
    gl.glDeleteVertexArrays(1, &m_vao);
    m_vao = 0;
    m_pointsProgram.reset();
    m_visibilityProgram.reset();
    m_accumulateProgram.reset();
    m_normalizeProgram.reset();
    m_initialized = false;
}

void CloudNode::evaluateFront(RenderContext& context) {
    const RenderSettings& settings = *context.settings;
    FrontCamera camera;
    camera.viewProjection = context.projection * context.view;
    camera.eye = context.camera->eye();
    camera.pixelsPerUnitAtUnitDistance = context.camera->screenScale(context.heightPx);
    camera.orthographic = context.camera->orthographic();
    if (settings.clip) {
        camera.clip = toUnitCube(*settings.clip, m_hierarchy->cloud().cube());
    }
    FrontOptions options;
    options.projectionThresholdPx = settings.projectionThresholdPx;
    options.pointBudget = settings.pointBudget;
    options.cpuBudgetMs = context.settle ? 0.0 : settings.frontBudgetMs;

    const NodeResidency* residency = m_hierarchy->residency();
    QElapsedTimer timer;
    timer.start();
    std::uint64_t pendingBefore = 0;
    if (!context.settle) {
        // Loads that finish during the evaluation are only seen by the next one.
        pendingBefore = residency != nullptr ? residency->stats().pendingLoads : 0;
        m_front->evaluate(camera, options);
    } else {
        // A screenshot: everything the threshold asks for; paged points, the nodes too.
        pendingBefore =
            settleFront(*m_front, camera, options,
                        residency != nullptr ? SettleLimits{INT_MAX, kMaxPagedSettleSeconds}
                                             : SettleLimits{kMaxSettleEvaluations})
                .pendingBefore;
    }
    if (residency != nullptr) {
        const ResidencyStats paged = residency->stats();
        context.stats->pagedPoints = true;
        context.stats->pendingLoads = std::max(pendingBefore, paged.pendingLoads);
        context.stats->pagedResidentBytes = paged.residentBytes;
        context.stats->pagedBudgetBytes = paged.budgetBytes;
    }
    context.stats->frontMs = static_cast<double>(timer.nsecsElapsed()) * 1e-6;
    context.stats->frontNodes = m_front->entries().size();
    const std::span<const std::size_t> perLevel = m_front->entriesPerLevel();
    std::copy(perLevel.begin(), perLevel.end(), context.stats->frontNodesPerLevel.begin());
    context.stats->placeholders = m_front->placeholderCount();
    // The widget measures leaf -> drawn itself (recordFirstDraws); the front's own
    // leaf -> substituted delays would only pile up.
    (void)m_front->takeSubstitutionDelays();
    (void)m_front->takeSubstitutionEvaluationDelays();
}

void CloudNode::recordFirstDraws() {
    m_drawnRanges.clear();
    for (const DrawItem& item : m_drawList) {
        if (item.buffer != nullptr) {
            const OctreeNode& node = m_hierarchy->node(item.level, item.index);
            m_drawnRanges.push_back({node.coveredBegin, node.coveredCount});
        }
    }
    m_firstDraws.markDrawn(*m_hierarchy, m_drawnRanges, FirstDrawTracker::Clock::now());
}

const OctreeNode& CloudNode::nodeOf(const DrawItem& item) const {
    return m_hierarchy->node(item.level, item.index);
}

void CloudNode::collectDrawList(RenderContext& context) {
    m_drawList.clear();
    const double capacity =
        std::max<double>(1.0, static_cast<double>(m_hierarchy->cloud().capacity()));
    for (const FrontEntry& entry : m_front->entries()) {
        if (entry.placeholder || !entry.visible) {
            continue;
        }
        const int level = entry.level();
        const OctreeNode& node = m_hierarchy->node(level, entry.index);
        if (node.pointCount == 0) {
            continue;
        }
        // Input arrives in Morton order, so where a node's points start in the sorted cloud
        // is when the sweep reached it: the build-age colour shows the oblique sweep.
        const float age = static_cast<float>(node.coveredBegin / capacity);
        const NodeBufferCache::Key key = NodeBufferCache::key(level, entry.index);
        m_drawList.push_back({key, level, entry.index, age, m_cache.use(key, m_frame)});
    }

    // Upload what is missing, coarse nodes first (they cover the most screen per byte),
    // within the per-frame budget.
    std::vector<DrawItem*> missing;
    for (DrawItem& item : m_drawList) {
        if (item.buffer == nullptr) {
            missing.push_back(&item);
        }
    }
    std::stable_sort(missing.begin(), missing.end(),
                     [](const DrawItem* a, const DrawItem* b) { return a->level < b->level; });
    // Nodes are packed (splat attributes estimated) in parallel, a batch at a time, then
    // uploaded here on the GL thread.
    std::size_t uploadedBytes = 0;
    std::size_t next = 0;
    while (next < missing.size() &&
           (context.settle || uploadedBytes < context.settings->uploadBudgetBytes)) {
        const std::size_t batchBegin = next;
        std::size_t batchBytes = 0;
        while (
            next < missing.size() && (next == batchBegin || batchBytes < kPackBatchBytes) &&
            (context.settle || uploadedBytes + batchBytes < context.settings->uploadBudgetBytes)) {
            batchBytes += std::size_t{nodeOf(*missing[next]).pointCount} * sizeof(PointVertex);
            ++next;
        }
        const std::size_t batchSize = next - batchBegin;
        m_packNodes.clear();
        for (std::size_t i = batchBegin; i < next; ++i) {
            m_packNodes.push_back(&nodeOf(*missing[i]));
        }
        if (!m_gpsTimeBase) {
            // Fixed for the cloud's life: uploaded vertices are relative to it.
            m_gpsTimeBase = gpsTimeBaseOf(*m_hierarchy, *m_packNodes.front());
        }
        m_gpsTimes.add(packNodesVertices(*m_hierarchy, m_packNodes, m_packed, *m_gpsTimeBase));
        for (std::size_t i = 0; i < batchSize; ++i) {
            DrawItem* item = missing[batchBegin + i];
            item->buffer = &m_cache.upload(*context.gl, item->key, m_packed[i], m_frame);
            uploadedBytes += item->buffer->bytes;
            ++context.stats->uploads;
        }
    }
}

void CloudNode::uploadPreview(QOpenGLExtraFunctions& gl) {
    if (m_previewVertices.empty()) {
        return;
    }
    if (m_previewVbo == 0) {
        gl.glGenBuffers(1, &m_previewVbo);
    }
    gl.glBindBuffer(GL_ARRAY_BUFFER, m_previewVbo);
    gl.glBufferData(GL_ARRAY_BUFFER,
                    static_cast<GLsizeiptr>(m_previewVertices.size() * sizeof(PointVertex)),
                    m_previewVertices.data(), GL_DYNAMIC_DRAW);
    gl.glBindBuffer(GL_ARRAY_BUFFER, 0);
    m_previewCount = static_cast<int>(m_previewVertices.size());
    m_previewVertices.clear();
}

bool CloudNode::hasColor() const {
    return m_hierarchy && m_hierarchy->cloud().attributes().has(Attribute::Color);
}

int CloudNode::effectiveColorMode(const RenderSettings& settings) const {
    ColorMode mode = settings.color;
    const bool lasOnly = mode == ColorMode::Classification || mode == ColorMode::ReturnNumber ||
                         mode == ColorMode::GpsTime;
    if (!m_hierarchy && lasOnly) {
        mode = ColorMode::Height; // the preview sample carries no LAS fields
    }
    if (m_hierarchy) {
        const AttributeSet attributes = m_hierarchy->cloud().attributes();
        const bool lasMode = mode == ColorMode::Classification || mode == ColorMode::ReturnNumber;
        if ((mode == ColorMode::Rgb && !attributes.has(Attribute::Color)) ||
            (mode == ColorMode::Intensity && !attributes.has(Attribute::Intensity)) ||
            (lasMode && !attributes.has(Attribute::Las)) ||
            (mode == ColorMode::GpsTime && !attributes.has(Attribute::GpsTime))) {
            mode = ColorMode::Height; // what Potree and CloudCompare show for plain xyz
        }
    }
    return static_cast<int>(mode);
}

void CloudNode::setCommonUniforms(QOpenGLShaderProgram& program, const RenderContext& context,
                                  float depthOffset) {
    const RenderSettings& settings = *context.settings;
    program.setUniformValue("u_view",
                            QMatrix4x4(glm::value_ptr(glm::mat4(context.view))).transposed());
    program.setUniformValue("u_projection",
                            QMatrix4x4(glm::value_ptr(glm::mat4(context.projection))).transposed());
    program.setUniformValue("u_pixelsPerUnit",
                            static_cast<float>(context.camera->screenScale(context.heightPx)));
    program.setUniformValue("u_orthographic", context.camera->orthographic());
    program.setUniformValue("u_sizeScale", settings.pointSizeScale);
    program.setUniformValue("u_minPointPx", kMinPointPx);
    program.setUniformValue("u_maxPointPx", kMaxPointPx);
    program.setUniformValue("u_depthOffset", depthOffset);
    program.setUniformValue("u_colorMode", effectiveColorMode(settings));
    // The clip box in the unit cube of the cloud drawn (the preview before a hierarchy: the
    // box is in source units, so it waits for the hierarchy's cube).
    const bool clipped = settings.clip.has_value() && m_hierarchy != nullptr;
    program.setUniformValue("u_clipEnabled", clipped);
    if (clipped) {
        const glm::mat4 clip =
            toUnitCube(*settings.clip, m_hierarchy->cloud().cube()).toBoxMatrix();
        program.setUniformValue("u_clip", QMatrix4x4(glm::value_ptr(clip)).transposed());
    }
    const float low = hasBounds() ? static_cast<float>(m_boundsMin.z) : 0.0f;
    const float high = hasBounds() ? static_cast<float>(m_boundsMax.z) : 1.0f;
    program.setUniformValue("u_heightRange", QVector2D(low, high));
    program.setUniformValue("u_levelColor", QVector3D(1, 1, 1));
    program.setUniformValue("u_buildAge", 0.0f);
    // The GPS range grows with every upload; vertices already on the GPU follow through it.
    program.setUniformValue("u_gpsTimeRange", QVector2D(static_cast<float>(m_gpsTimes.min), static_cast<float>(m_gpsTimes.max)));
    QOpenGLExtraFunctions& gl = *context.gl;
    const int paletteLocation = program.uniformLocation("u_classColors");
    if (paletteLocation >= 0) {
        gl.glUniform1uiv(paletteLocation, kLasClassCount, classPalette().data());
    }
    program.setUniformValue("u_classFilter", settings.hiddenClasses.any());
    const int hiddenLocation = program.uniformLocation("u_hiddenClasses");
    if (hiddenLocation >= 0) {
        const auto words = hiddenClassWords(settings.hiddenClasses);
        gl.glUniform1uiv(hiddenLocation, static_cast<GLsizei>(words.size()), words.data());
    }
}

void CloudNode::bindVertexLayout(QOpenGLExtraFunctions& gl, unsigned vbo) {
    gl.glBindBuffer(GL_ARRAY_BUFFER, vbo);
    const auto stride = static_cast<GLsizei>(sizeof(PointVertex));
    gl.glEnableVertexAttribArray(0);
    gl.glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
    gl.glEnableVertexAttribArray(1);
    gl.glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride, reinterpret_cast<void*>(12));
    gl.glEnableVertexAttribArray(2);
    gl.glVertexAttribPointer(2, 4, GL_INT_2_10_10_10_REV, GL_TRUE, stride,
                             reinterpret_cast<void*>(16));
    gl.glEnableVertexAttribArray(3);
    gl.glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(20));
    gl.glEnableVertexAttribArray(4); // integers (uvec4 a_las), not normalised floats
    gl.glVertexAttribIPointer(4, 4, GL_UNSIGNED_BYTE, stride, reinterpret_cast<void*>(24));
    gl.glEnableVertexAttribArray(5);
    gl.glVertexAttribPointer(5, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(28));
}

void CloudNode::drawItems(RenderContext& context, QOpenGLShaderProgram& program) {
    QOpenGLExtraFunctions& gl = *context.gl;
    const int levelLocation = program.uniformLocation("u_levelColor");
    const int ageLocation = program.uniformLocation("u_buildAge");
    unsigned boundPage = 0;
    for (const DrawItem& item : m_drawList) {
        if (item.buffer == nullptr) {
            continue; // not uploaded yet (per-frame budget)
        }
        const glm::vec3 color = levelColor(item.level);
        program.setUniformValue(levelLocation, QVector3D(color.x, color.y, color.z));
        program.setUniformValue(ageLocation, item.buildAge);
        if (item.buffer->vbo != boundPage) {
            bindVertexLayout(gl, item.buffer->vbo);
            boundPage = item.buffer->vbo;
        }
        gl.glDrawArrays(GL_POINTS, item.buffer->firstPoint, item.buffer->pointCount);
    }
}

void CloudNode::drawPreview(RenderContext& context) {
    if (m_previewVbo == 0 || m_previewCount == 0) {
        return;
    }
    bindVertexLayout(*context.gl, m_previewVbo);
    context.gl->glDrawArrays(GL_POINTS, 0, m_previewCount);
}

void CloudNode::drawPoints(RenderContext& context) {
    QOpenGLExtraFunctions& gl = *context.gl;
    gl.glBindFramebuffer(GL_FRAMEBUFFER, context.targetFramebuffer);
    gl.glEnable(GL_DEPTH_TEST);
    gl.glDepthFunc(GL_LESS);
    gl.glDepthMask(GL_TRUE);
    m_pointsProgram->bind();
    setCommonUniforms(*m_pointsProgram, context, 0.0f);
    drawItems(context, *m_pointsProgram);
    if (m_drawList.empty()) {
        drawPreview(context);
    }
    m_pointsProgram->release();
}

void CloudNode::drawSplats(RenderContext& context) {
    QOpenGLExtraFunctions& gl = *context.gl;
    if (!m_splatTarget.ensureSize(gl, context.widthPx, context.heightPx)) {
        drawPoints(context); // no float render target on this driver: points are still right
        return;
    }
    // Pass 1: visibility (depth of the nearest surface, pushed back by a splat radius).
    gl.glBindFramebuffer(GL_FRAMEBUFFER, m_splatTarget.framebuffer());
    gl.glViewport(0, 0, context.widthPx, context.heightPx);
    gl.glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    gl.glClearDepthf(1.0f);
    gl.glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.glEnable(GL_DEPTH_TEST);
    gl.glDepthFunc(GL_LESS);
    gl.glDepthMask(GL_TRUE);
    gl.glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    m_visibilityProgram->bind();
    setCommonUniforms(*m_visibilityProgram, context, kSplatDepthOffsetRadii);
    drawItems(context, *m_visibilityProgram);
    if (m_drawList.empty()) {
        drawPreview(context);
    }

    // Pass 2: accumulation of Gaussian-weighted colours of the splats on that surface.
    gl.glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl.glDepthMask(GL_FALSE);
    gl.glDepthFunc(GL_LEQUAL);
    gl.glEnable(GL_BLEND);
    gl.glBlendFunc(GL_ONE, GL_ONE);
    m_accumulateProgram->bind();
    setCommonUniforms(*m_accumulateProgram, context, 0.0f);
    drawItems(context, *m_accumulateProgram);
    if (m_drawList.empty()) {
        drawPreview(context);
    }
    gl.glDisable(GL_BLEND);

    // Pass 3: normalisation into the frame, with the surface's depth.
    gl.glBindFramebuffer(GL_FRAMEBUFFER, context.targetFramebuffer);
    gl.glDepthMask(GL_TRUE);
    gl.glDepthFunc(GL_ALWAYS);
    m_normalizeProgram->bind();
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindTexture(GL_TEXTURE_2D, m_splatTarget.accumulationTexture());
    gl.glActiveTexture(GL_TEXTURE1);
    gl.glBindTexture(GL_TEXTURE_2D, m_splatTarget.depthTexture());
    m_normalizeProgram->setUniformValue("u_accumulation", 0);
    m_normalizeProgram->setUniformValue("u_depth", 1);
    gl.glDrawArrays(GL_TRIANGLES, 0, 3);
    gl.glBindTexture(GL_TEXTURE_2D, 0);
    gl.glActiveTexture(GL_TEXTURE0);
    gl.glBindTexture(GL_TEXTURE_2D, 0);
    gl.glDepthFunc(GL_LESS);
    m_normalizeProgram->release();
}

void CloudNode::drawComputePoints(RenderContext& context) {
    m_computeBatches.clear();
    for (const DrawItem& item : m_drawList) {
        if (item.buffer != nullptr) {
            m_computeBatches.push_back({item.buffer->vbo, item.buffer->firstPoint,
                                        item.buffer->pointCount, levelColor(item.level),
                                        item.buildAge});
        }
    }
    if (m_drawList.empty() && m_previewVbo != 0) {
        m_computeBatches.push_back({m_previewVbo, 0, m_previewCount, glm::vec3(1.0f), 0.0f});
    }
    const bool drawn = m_compute.draw(
        *context.gl, context.targetFramebuffer, context.widthPx, context.heightPx, m_computeBatches,
        [&](QOpenGLShaderProgram& program) {
            setCommonUniforms(program, context, 0.0f);
            program.setUniformValue(
                "u_viewProjection",
                QMatrix4x4(glm::value_ptr(glm::mat4(context.projection * context.view)))
                    .transposed());
        });
    if (!drawn) {
        drawPoints(context); // no OpenGL 4.3, or no per-pixel images at this size
    }
}

void CloudNode::render(RenderContext& context) {
    QOpenGLExtraFunctions& gl = *context.gl;
    ++m_frame;
    if (m_hierarchyChanged) {
        m_cache.clear(gl);
        m_hierarchyChanged = false;
    }
    uploadPreview(gl);

    m_drawList.clear();
    if (m_front) {
        evaluateFront(context);
        collectDrawList(context);
        context.stats->pointsTotal = m_hierarchy->cloud().capacity();
    }

    gl.glBindVertexArray(m_vao);
    gl.glEnable(GL_PROGRAM_POINT_SIZE);
    if (context.settings->mode == RenderMode::Splats) {
        drawSplats(context);
    } else if (context.settings->mode == RenderMode::ComputePoints) {
        drawComputePoints(context);
    } else {
        drawPoints(context);
    }
    if (m_front) {
        recordFirstDraws();
    }
    if (m_drawList.empty()) {
        context.stats->showingPreview = m_previewCount > 0;
        context.stats->pointsDrawn = static_cast<std::size_t>(m_previewCount);
    } else {
        for (const DrawItem& item : m_drawList) {
            if (item.buffer != nullptr) {
                context.stats->pointsDrawn += static_cast<std::size_t>(item.buffer->pointCount);
                ++context.stats->nodesDrawn;
            }
        }
    }
    gl.glBindVertexArray(0);
    gl.glBindBuffer(GL_ARRAY_BUFFER, 0);

    m_cache.evictTo(gl, context.settings->gpuMemoryBudgetBytes, m_frame);
    context.stats->gpuBytes = m_cache.bytesResident();
}

} // namespace omicron
