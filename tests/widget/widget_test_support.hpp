// Helpers of the widget tests (and of the application's GL tests): shared data paths,
// finished hierarchies, a generated scene sorted into ranges, image statistics.
#pragma once

#include "build/build_options.hpp"
#include "build/hierarchy.hpp"
#include "sort/morton_sorter.hpp"

#include <QColor>
#include <QImage>
#include <QString>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace omicron::test {

// Path of a file in ../shared/data; empty when it is absent (the test then skips).
QString sharedDataFile(const char* name);

// Reads, sorts and builds `path` completely (pipeline 1), like the application does.
std::shared_ptr<const Hierarchy> buildHierarchy(const QString& path, const BuildOptions& options);

// The built-in generated scene, sorted by the real incremental sorter in ranges of
// `rangePoints`: a test feeds the ranges to a HierarchyBuilder at its own pace.
struct SortedScene {
    std::unique_ptr<IncrementalMortonSorter> sorter;
    std::vector<std::pair<std::size_t, std::size_t>> ranges;
    std::shared_ptr<const SortedCloud> cloud() const { return sorter->cloud(); }
};
SortedScene sortGeneratedScene(std::size_t points, std::uint64_t seed,
                               std::size_t rangePoints = 10'000);

// Pixels of `image` in the node highlight's magenta (red and blue high, green low).
int magentaPixels(const QImage& image);

// Fraction of pixels of `image` that differ from `background` (the cloud's coverage).
double coverage(const QImage& image, const QColor& background);

// The CloudView's clear colour.
QColor viewBackground();

// Pixels of `image` within `tolerance` (sum of the channels' differences) of `color`.
int pixelsNear(const QImage& image, const QColor& color, int tolerance = 12);

// A classified LAS 1.4 (point format 6) test cloud at `path`: a flat 40 x 40 grid of points
// 1 m apart (x = 300000 + i, y = 5000000 + j, z = 50), class 2 (Ground) where i < 20 and
// class 6 (Building) where i >= 20; return number j % 4 + 1 of 4; GPS time 4e8 + 10 i (a
// ramp along x at a magnitude a float would not resolve to the second). `oneClass`: every
// point class 6, return 1 of 1, GPS time 4e8, so that every LAS record is the same (a uniform
// column, stored once by the sorter). Throws on failure.
void writeClassifiedLas(const QString& path, bool oneClass = false);
inline constexpr int kClassifiedLasPointsPerClass = 800;

} // namespace omicron::test
