// Builds the renderer's shader programs from the GLSL files in shaders/ (Qt resources):
// prepends the GLSL version and the shared snippets a program needs. A compile or link error
// throws std::runtime_error with the shader's name and the driver's log.
#pragma once

#include <QOpenGLShaderProgram>
#include <QString>
#include <QStringList>
#include <memory>

namespace omicron {

struct ShaderSources {
    QString vertex;            // file name under :/omicron/shaders/
    QString fragment;
    QStringList vertexSnippets = {};   // prepended to the vertex stage, in this order
    QStringList fragmentSnippets = {}; // prepended to the fragment stage
};

std::unique_ptr<QOpenGLShaderProgram> buildShaderProgram(const ShaderSources& sources);

// A compute program (GLSL 430 core, OpenGL 4.3): `snippets` then `compute`, as above.
std::unique_ptr<QOpenGLShaderProgram> buildComputeProgram(const QString& compute,
                                                          const QStringList& snippets = {});

} // namespace omicron
