#include "widget_test_support.hpp"

#include "io/las/las_writer.hpp"
#include "pipeline/build_pipeline.hpp"
#include "points/las_fields.hpp"
#include "scene/scene_generator.hpp"

#include <QFileInfo>
#include <cstdlib>

namespace omicron::test {

QString sharedDataFile(const char* name) {
    const QString path = QStringLiteral(OMICRON_SHARED_DATA_DIR "/") + QString::fromUtf8(name);
    return QFileInfo::exists(path) ? path : QString();
}

std::shared_ptr<const Hierarchy> buildHierarchy(const QString& path, const BuildOptions& options) {
    BuildPipeline pipeline;
    pipeline.run(path.toStdString(), {options, kDefaultSortChunks});
    return pipeline.hierarchy();
}

SortedScene sortGeneratedScene(std::size_t points, std::uint64_t seed, std::size_t rangePoints) {
    const GeneratedScene scene = generateScene(points, seed);
    CloudInfo info;
    info.pointCount = scene.points.size();
    info.attributes = scene.points.attributes;
    info.sourceBounds = scene.sourceBounds;
    info.cube = scene.cube;
    SortOptions sortOptions;
    sortOptions.batchPoints = rangePoints;
    SortedScene sorted;
    sorted.sorter = std::make_unique<IncrementalMortonSorter>(info, sortOptions);
    sorted.sorter->add(scene.points);
    sorted.sorter->sortAndEmit([&](const SortedCloud&, std::size_t begin, std::size_t end) {
        sorted.ranges.emplace_back(begin, end);
    });
    return sorted;
}

int magentaPixels(const QImage& image) {
    int count = 0;
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            const QColor c = image.pixelColor(x, y);
            count += c.red() > 200 && c.blue() > 200 && c.green() < 80 ? 1 : 0;
        }
    }
    return count;
}

double coverage(const QImage& image, const QColor& background) {
    const QImage rgb = image.convertToFormat(QImage::Format_RGB32);
    const QRgb clear = background.rgb();
    std::size_t covered = 0;
    for (int y = 0; y < rgb.height(); ++y) {
        const auto* line = reinterpret_cast<const QRgb*>(rgb.constScanLine(y));
        for (int x = 0; x < rgb.width(); ++x) {
            const QRgb pixel = line[x];
            const int difference = std::abs(qRed(pixel) - qRed(clear)) +
                                   std::abs(qGreen(pixel) - qGreen(clear)) +
                                   std::abs(qBlue(pixel) - qBlue(clear));
            covered += difference > 24 ? 1 : 0;
        }
    }
    return static_cast<double>(covered) / std::max(1, rgb.width() * rgb.height());
}

QColor viewBackground() {
    return QColor::fromRgbF(0.11f, 0.12f, 0.14f);
}

int pixelsNear(const QImage& image, const QColor& color, int tolerance) {
    const QImage rgb = image.convertToFormat(QImage::Format_RGB32);
    int count = 0;
    for (int y = 0; y < rgb.height(); ++y) {
        const auto* line = reinterpret_cast<const QRgb*>(rgb.constScanLine(y));
        for (int x = 0; x < rgb.width(); ++x) {
            const QRgb pixel = line[x];
            const int difference = std::abs(qRed(pixel) - color.red()) +
                                   std::abs(qGreen(pixel) - color.green()) +
                                   std::abs(qBlue(pixel) - color.blue());
            count += difference <= tolerance ? 1 : 0;
        }
    }
    return count;
}

void writeClassifiedLas(const QString& path, bool oneClass) {
    constexpr int kSide = 40;
    Bounds bounds;
    bounds.extend(glm::dvec3(300000.0, 5000000.0, 50.0));
    bounds.extend(glm::dvec3(300000.0 + kSide - 1, 5000000.0 + kSide - 1, 50.0));
    const CubeTransform cube = CubeTransform::fromBounds(bounds);
    PointBatch batch;
    batch.attributes = AttributeSet(Attribute::Las) | Attribute::GpsTime;
    const std::size_t stride = batch.attributes.lasBytes();
    for (int j = 0; j < kSide; ++j) {
        for (int i = 0; i < kSide; ++i) {
            batch.positions.push_back(cube.toUnit(glm::dvec3(300000.0 + i, 5000000.0 + j, 50.0)));
            LasFields fields;
            fields.classification = i < kSide / 2 && !oneClass ? 2 : 6;
            fields.returns =
                static_cast<std::uint8_t>(oneClass ? 1 | (1 << 4) : (j % 4 + 1) | (4 << 4));
            fields.gpsTime = oneClass ? 4e8 : 4e8 + 10.0 * i;
            batch.las.resize(batch.las.size() + stride);
            encodeLasFields(batch.attributes, fields, batch.las.data() + batch.las.size() - stride);
        }
    }
    LasWriteOptions options;
    options.versionMinor = 4;
    options.pointFormat = 6;
    options.offset = glm::dvec3(300000.0, 5000000.0, 0.0);
    writeLas(path.toStdString(), batch, cube, options);
}

} // namespace omicron::test
