#include "shader_library.hpp"

#include <QFile>
#include <stdexcept>

namespace omicron {

namespace {

// GLSL 3.30 core: what every OpenGL 3.3+ driver (Mesa llvmpipe included) compiles.
constexpr const char* kVersionLine = "#version 330 core\n";

QByteArray readShaderFile(const QString& name) {
    QFile file(QStringLiteral(":/omicron/shaders/") + name);
    if (!file.open(QIODevice::ReadOnly)) {
        throw std::runtime_error("shader resource missing: " + name.toStdString());
    }
    return file.readAll();
}

QByteArray composeStage(const QStringList& snippets, const QString& stageFile) {
    QByteArray text(kVersionLine);
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
    if (!program->addShaderFromSourceCode(QOpenGLShader::Vertex,
                                          composeStage(sources.vertexSnippets, sources.vertex))) {
        fail(sources.vertex);
    }
    if (!program->addShaderFromSourceCode(QOpenGLShader::Fragment,
                                          composeStage(sources.fragmentSnippets, sources.fragment))) {
        fail(sources.fragment);
    }
    if (!program->link()) {
        fail(sources.vertex + "+" + sources.fragment);
    }
    return program;
}

} // namespace omicron
