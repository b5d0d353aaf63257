// Embedding omicron's viewer in a Qt application: build a hierarchy on a background thread
// and show it while it grows. Usage: omicron-embed-example CLOUD [--snapshot OUT.png]
// (--snapshot saves one frame once the build is done and quits: used by the test suite).
#include "build/hierarchy_builder.hpp"
#include "cloud_view.hpp"
#include "io/point_reader.hpp"
#include "sort/morton_sorter.hpp"

#include <QApplication>
#include <QImage>
#include <QTimer>
#include <cstdio>
#include <thread>

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    const QStringList args = app.arguments();
    if (args.size() < 2) {
        std::fprintf(stderr, "usage: omicron-embed-example CLOUD [--snapshot OUT.png]\n");
        return 2;
    }
    const int snapshotFlag = static_cast<int>(args.indexOf("--snapshot"));
    const QString snapshot = snapshotFlag > 0 && snapshotFlag + 1 < args.size() ? args[snapshotFlag + 1] : QString();

    // The pipeline: reader -> incremental Morton sorter -> oblique-cut builder.
    std::unique_ptr<omicron::PointReader> reader;
    try {
        reader = omicron::openPointCloud(args[1].toStdString());
    } catch (const std::exception& error) {
        std::fprintf(stderr, "%s\n", error.what());
        return 1;
    }
    omicron::IncrementalMortonSorter sorter(reader->info(), omicron::SortOptions{});
    omicron::HierarchyBuilder builder(sorter.cloud(), omicron::BuildOptions{});

    // The widget: give it the hierarchy now; it draws whatever is renderable, frame by frame.
    omicron::CloudView view;
    view.setHierarchy(builder.sharedHierarchy());
    view.resize(1024, 768);
    if (snapshot.isEmpty()) {
        view.show();
    }

    std::thread pipeline([&] {
        try {
            reader->read([&](const omicron::PointBatch& batch) { sorter.add(batch); });
            sorter.sortAndEmit(builder.consumer());
        } catch (const std::exception& error) {
            std::fprintf(stderr, "%s\n", error.what()); // the view keeps what was built
        }
        builder.finish();
    });

    if (!snapshot.isEmpty()) {
        QTimer::singleShot(0, [&] {
            builder.wait();
            const QImage image = view.renderImage(QSize(640, 480));
            app.exit(!image.isNull() && image.save(snapshot) ? 0 : 1);
        });
    }
    const int status = app.exec();
    builder.cancel();
    pipeline.join();
    return status;
}
