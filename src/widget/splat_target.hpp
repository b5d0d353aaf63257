// The offscreen target of the surface-splat passes: a float colour texture that accumulates
// weighted colours and weights, and a depth texture holding the visible surface (pass 1),
// which pass 3 writes back into the frame so overlays are hidden by the surface.
#pragma once

#include <QOpenGLExtraFunctions>

namespace omicron {

class SplatTarget {
public:
    // (Re)creates the textures when the size changed. Returns false (and leaves the target
    // unusable) when the driver cannot render to a float texture.
    bool ensureSize(QOpenGLExtraFunctions& gl, int widthPx, int heightPx);
    void release(QOpenGLExtraFunctions& gl);

    unsigned framebuffer() const { return m_framebuffer; }
    unsigned accumulationTexture() const { return m_accumulation; }
    unsigned depthTexture() const { return m_depth; }

private:
    unsigned m_framebuffer = 0;
    unsigned m_accumulation = 0;
    unsigned m_depth = 0;
    int m_widthPx = 0;
    int m_heightPx = 0;
    bool m_complete = false;
};

} // namespace omicron
