// Helpers of the widget tests: shared data paths, finished hierarchies, image statistics.
#pragma once

#include "build_options.hpp"
#include "hierarchy.hpp"

#include <QColor>
#include <QImage>
#include <QString>
#include <memory>

namespace omicron::test {

// Path of a file in ../shared/data; empty when it is absent (the test then skips).
QString sharedDataFile(const char* name);

// Reads, sorts and builds `path` completely (pipeline 1), like the application does.
std::shared_ptr<const Hierarchy> buildHierarchy(const QString& path, const BuildOptions& options);

// Fraction of pixels of `image` that differ from `background` (the cloud's coverage).
double coverage(const QImage& image, const QColor& background);

// The CloudView's clear colour.
QColor viewBackground();

} // namespace omicron::test
