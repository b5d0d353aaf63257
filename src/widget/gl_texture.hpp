// A 2D texture for an offscreen target: nearest filtering, clamped edges, no data yet
// (the splat passes' and eye-dome lighting's colour and depth targets).
#pragma once

#include <QOpenGLExtraFunctions>

namespace omicron {

inline void makeTargetTexture(QOpenGLExtraFunctions& gl, unsigned& texture, GLint internalFormat,
                              GLenum format, GLenum type, int widthPx, int heightPx) {
    gl.glGenTextures(1, &texture);
    gl.glBindTexture(GL_TEXTURE_2D, texture);
    gl.glTexImage2D(GL_TEXTURE_2D, 0, internalFormat, widthPx, heightPx, 0, format, type, nullptr);
    gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

} // namespace omicron
