// Fixture: OpenGL through Qt in the core.
#pragma once
#include <QOpenGLFunctions>
