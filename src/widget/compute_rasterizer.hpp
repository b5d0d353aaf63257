// The compute-shader point rasterizer (OpenGL 4.3): points drawn by compute passes into
// per-pixel images instead of GL_POINTS, after Schütz, Kerbl and Wimmer (2021), with the
// footprint, colours and depth of the points mode, so it can replace that mode wherever a
// driver is faster with it.
//
// Passes of a frame, one dispatch per pass and per page of node vertices (NodeBufferCache)
// that holds drawn nodes:
//   0 clear   the depth image to "empty" (a framebuffer clear)
//   1 depth   (compute_depth.comp): per point, its round footprint; imageAtomicMin of the
//             window depth (float bits) into the R32UI depth image
//   2 colour  (compute_color.comp): the same footprint again; where the pixel's depth is the
//             point's own, the point stores its colour (colour modes of color.glsl) into the
//             RGBA8 colour image
//   3 resolve (compute_resolve.frag): a full-screen triangle writes colour and gl_FragDepth of
//             covered pixels into the target framebuffer (overlays and picking see the points)
//
// Why two passes of 32-bit atomics and not Schütz's single atomicMin on 64 bits
// (depth << 32 | colour): 64-bit atomics need GL_NV_shader_atomic_int64, which Mesa
// llvmpipe, the CI's and most dev machines' renderer, does not offer (it has
// GL_ARB_gpu_shader_int64 arithmetic, no 64-bit atomics). Packing depth and colour into 32 bits
// leaves either a 16-bit depth (overlapping surfaces z-fight at scan scale) or a palette colour; a
// second pass keeps the full depth and 8-bit RGB, for a second read of the points.
//
// The pages of NodeBufferCache are read as they are (buffer textures over the same buffer
// objects, no copy); a draw table of this frame's nodes (first point, level colour, build age)
// and a chunk table (the first node of each 128-invocation workgroup) map invocations to points.
#pragma once

#include <QOpenGLExtraFunctions>
#include <QOpenGLShaderProgram>
#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <memory>
#include <vector>

class QOpenGLContext;

namespace omicron {

class ComputeRasterizer {
public:
    // A range of a vertex buffer to draw (a node in its page, or the preview) and its
    // per-node colour inputs.
    struct Batch {
        unsigned buffer = 0;
        int firstPoint = 0;
        int pointCount = 0;
        glm::vec3 levelColor{1.0f};
        float buildAge = 0.0f;
    };

    // Setting this environment variable (to anything but 0) makes every view draw
    // ComputePoints with GL_POINTS, as on a context without compute shaders.
    static constexpr const char* kDisableEnvironmentVariable = "OMICRON_DISABLE_COMPUTE_POINTS";

    // Compiles the passes when `context` offers OpenGL 4.3 (compute shaders, image atomics)
    // and the environment does not disable them; otherwise, or when a pass does not compile,
    // stays unavailable (the caller draws GL_POINTS) and says why on the log.
    void initializeGL(QOpenGLContext& context);
    void release(QOpenGLExtraFunctions& gl);
    bool available() const { return m_depthProgram != nullptr; }
    // GL_MAX_TEXTURE_BUFFER_SIZE in bytes of RGBA32UI texels (0 while unavailable): the largest
    // page it can read.
    std::size_t maxPageBytes() const { return m_maxPageBytes; }

    // Draws `batches` into `targetFramebuffer` (depth test on, depth written). `setUniforms`
    // sets the view, size and colour-mode uniforms shared with the points mode on each program.
    // Returns false, drawing nothing, when the per-pixel images cannot be made at this size.
    bool draw(QOpenGLExtraFunctions& gl, unsigned targetFramebuffer, int widthPx, int heightPx,
              const std::vector<Batch>& batches,
              const std::function<void(QOpenGLShaderProgram&)>& setUniforms);

private:
    // Mirrors DrawNode of compute_points.glsl (one RGBA32UI texel).
    struct DrawNode {
        std::uint32_t firstInvocation = 0;
        std::uint32_t firstPoint = 0;
        std::uint32_t levelColor = 0;
        float buildAge = 0.0f;
    };
    struct Dispatch {
        unsigned buffer = 0;
        std::uint32_t invocations = 0;
        std::uint32_t nodeBase = 0;
        std::uint32_t chunkBase = 0;
    };

    bool ensureSize(QOpenGLExtraFunctions& gl, int widthPx, int heightPx);
    void buildTables(const std::vector<Batch>& batches);
    void uploadTables(QOpenGLExtraFunctions& gl);
    void dispatchPass(QOpenGLExtraFunctions& gl, QOpenGLShaderProgram& program);
    void releaseTargets(QOpenGLExtraFunctions& gl);
    // Zero the handles (after deleting them, or when their context is gone).
    void forgetTargets();
    void forgetObjects();

    std::unique_ptr<QOpenGLShaderProgram> m_depthProgram;
    std::unique_ptr<QOpenGLShaderProgram> m_colorProgram;
    std::unique_ptr<QOpenGLShaderProgram> m_resolveProgram;
    unsigned m_depthImage = 0;       // R32UI
    unsigned m_colorImage = 0;       // RGBA8
    unsigned m_clearFramebuffer = 0; // the depth image as its colour attachment
    int m_widthPx = 0;
    int m_heightPx = 0;
    bool m_targetsComplete = false;
    unsigned m_drawNodeBuffer = 0;
    unsigned m_chunkBuffer = 0;
    unsigned m_pageTexture = 0;     // buffer texture views: page points (re-pointed per page),
    unsigned m_drawNodeTexture = 0; // draw table,
    unsigned m_chunkTexture = 0;    // chunk table
    std::size_t m_maxPageBytes = 0;
    std::vector<DrawNode> m_drawNodes;
    std::vector<std::uint32_t> m_chunkFirstNode;
    std::vector<Dispatch> m_dispatches;
    std::vector<std::size_t> m_order;
};

} // namespace omicron
