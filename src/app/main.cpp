// omicron: the desktop application. `omicron [FILE]` opens FILE (PLY, LAS, XYZ, .oms, .omh);
// without one it shows the built-in generated scene, so the program shows something at once.
#include "cloud_view.hpp"
#include "main_window.hpp"

#include <QApplication>
#include <QCommandLineParser>
#include <QIcon>
#include <cstdlib>

int main(int argc, char* argv[]) {
    // CloudView needs a core profile context; it must be the default before the first widget.
    omicron::useCoreProfileByDefault();

    QApplication app(argc, argv);
    QApplication::setOrganizationName(QStringLiteral("omicron"));
    QApplication::setApplicationName(QStringLiteral("omicron"));
    QApplication::setApplicationVersion(QStringLiteral(OMICRON_VERSION));
    QApplication::setWindowIcon(QIcon(QStringLiteral(":/omicron/omicron.svg")));

    QCommandLineParser parser;
    parser.setApplicationDescription(
        QStringLiteral("View a point cloud while its OMiCroN level-of-detail hierarchy is built."));
    parser.addHelpOption();
    parser.addVersionOption();
    parser.addPositionalArgument(QStringLiteral("FILE"),
                                 QStringLiteral("PLY, LAS, XYZ, .oms or .omh file (default: the "
                                                "built-in generated scene)"),
                                 QStringLiteral("[FILE]"));
    QCommandLineOption pointsOption(
        QStringLiteral("scene-points"),
        QStringLiteral("Points of the generated default scene (default %1).")
            .arg(omicron::kDefaultScenePoints),
        QStringLiteral("N"));
    parser.addOption(pointsOption);
    parser.process(app);
    if (parser.positionalArguments().size() > 1) {
        parser.showHelp(2);
    }

    omicron::MainWindow window;
    window.show();
    if (!parser.positionalArguments().isEmpty()) {
        window.openFile(parser.positionalArguments().first());
    } else {
        bool ok = true;
        const quint64 points = parser.isSet(pointsOption)
                                   ? parser.value(pointsOption).toULongLong(&ok)
                                   : omicron::kDefaultScenePoints;
        if (!ok || points == 0) {
            std::fprintf(stderr, "omicron: --scene-points takes a positive integer, found '%s'\n",
                         qPrintable(parser.value(pointsOption)));
            return 2;
        }
        window.openDefaultScene(points);
    }
    return app.exec();
}
