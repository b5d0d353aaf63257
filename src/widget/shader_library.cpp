#include "shader_library.hpp"

#include <QFile>
#include <stdexcept>

namespace omicron {

namespace {

// GLSL 3.30 core: what every OpenGL 3.3+ driver (Mesa llvmpipe included) compiles; compute
// shaders (the compute point rasterizer, OpenGL 4.3) need 4.30.
constexpr const char* kVersion = "330 core";
constexpr const char* kComputeVersion = "430 core";

QByteArray readShaderFile(const QString& name) {
    QFile file(QStringLiteral(":/omicron/shaders/") + name);
    if (!file.open(QIODevice::ReadOnly)) {
        throw std::runtime_error("shader resource missing: " + name.toStdString());
    }
    return file.readAll();
}

QByteArray composeStage(const char* version, const QStringList& snippets,
                        const QString& stageFile) {
    QByteArray text = QByteArray("#version ") + version + "\n";
    for (const QString& snippet : snippets) {
        text += readShaderFile(snippet);
        text += '\n';
    }
    text += readShaderFile(stageFile);
    return text;
}

} // namespace

std::unique_ptr<QOpenGLShaderProgram> buildShaderProgram(const ShaderSources& sources) {
    auto program = std::make_unique<QOpenGLShaderProgram>();
    const auto fail = [&](const QString& stage) {
        throw std::runtime_error("shader " + stage.toStdString() + " failed: " +
                                 program->log().toStdString());
    };
    if (!program->addShaderFromSourceCode(
            QOpenGLShader::Vertex, composeStage(kVersion, sources.vertexSnippets, sources.vertex))) {
        fail(sources.vertex);
    }
    if (!program->addShaderFromSourceCode(
            QOpenGLShader::Fragment,
            composeStage(kVersion, sources.fragmentSnippets, sources.fragment))) {
        fail(sources.fragment);
    }
    if (!program->link()) {
        fail(sources.vertex + "+" + sources.fragment);
    }
    return program;
}

std::unique_ptr<QOpenGLShaderProgram> buildComputeProgram(const QString& compute,
                                                          const QStringList& snippets) {
    auto program = std::make_unique<QOpenGLShaderProgram>();
    if (!program->addShaderFromSourceCode(QOpenGLShader::Compute,
                                          composeStage(kComputeVersion, snippets, compute)) ||
        !program->link()) {
        throw std::runtime_error("shader " + compute.toStdString() +
                                 " failed: " + program->log().toStdString());
    }
    return program;
}

} // namespace omicron
