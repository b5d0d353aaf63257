// The programs that render through CloudView, run as a user would: `omicron-cli render` and
// the embedding example, each producing a PNG whose pixels are checked.
#include "widget_test_support.hpp"

#include <QDir>
#include <QProcess>
#include <QTemporaryDir>
#include <QtTest>

using namespace omicron;

namespace {

struct Run {
    int exitCode = -1;
    QString output;
};

Run runProgram(const QString& program, const QStringList& arguments) {
    QProcess process;
    process.setProcessChannelMode(QProcess::MergedChannels);
    process.start(program, arguments);
    Run run;
    if (!process.waitForFinished(300000)) {
        process.kill();
        process.waitForFinished();
        run.output = "timed out";
        return run;
    }
    run.exitCode = process.exitStatus() == QProcess::NormalExit ? process.exitCode() : -1;
    run.output = QString::fromUtf8(process.readAll());
    return run;
}

} // namespace

class tst_RenderProgramsGL : public QObject {
    Q_OBJECT
private slots:
    void cliRendersTheLionFromTheFront() {
        const QString lion = test::sharedDataFile("lion.ply");
        if (lion.isEmpty()) {
            QSKIP("../shared/data/lion.ply is absent");
        }
        QTemporaryDir dir;
        const QString out = dir.filePath("lion.png");
        const Run run = runProgram(OMICRON_CLI_PATH, {"render", lion, "--camera", "front",
                                                      "--size", "320x240", out});
        QVERIFY2(run.exitCode == 0, qPrintable(run.output));
        QVERIFY2(run.output.contains("rendered"), qPrintable(run.output));
        const QImage image(out);
        QCOMPARE(image.size(), QSize(320, 240));
        const double covered = test::coverage(image, test::viewBackground());
        QVERIFY2(covered > 0.05 && covered < 0.6, qPrintable(QString::number(covered)));
        // Nothing but the image is left in the folder (no temporary file).
        QCOMPARE(QDir(dir.path()).entryList(QDir::Files), QStringList{"lion.png"});
    }

    // A .omh beyond --memory-budget renders with its points paged in on demand: the same
    // image framing, the nodes it needed read and the rest never loaded.
    void cliRendersAPagedHierarchyUnderItsBudget() {
        const QString lion = test::sharedDataFile("lion.ply");
        if (lion.isEmpty()) {
            QSKIP("../shared/data/lion.ply is absent");
        }
        QTemporaryDir dir;
        const QString omh = dir.filePath("lion.omh");
        Run run = runProgram(OMICRON_CLI_PATH, {"build", lion, "--save", omh});
        QVERIFY2(run.exitCode == 0, qPrintable(run.output));
        const QString whole = dir.filePath("whole.png");
        run = runProgram(OMICRON_CLI_PATH,
                         {"render", omh, "--camera", "front", "--size", "320x240", whole});
        QVERIFY2(run.exitCode == 0, qPrintable(run.output));
        QVERIFY2(!run.output.contains("paged"), qPrintable(run.output));
        const QString paged = dir.filePath("paged.png");
        run = runProgram(OMICRON_CLI_PATH, {"render", omh, "--camera", "front", "--size",
                                            "320x240", "--memory-budget", "4M", paged});
        QVERIFY2(run.exitCode == 0, qPrintable(run.output));
        QVERIFY2(run.output.contains("points paged in on demand"), qPrintable(run.output));
        QVERIFY2(run.output.contains("of a 4.0 MiB budget"), qPrintable(run.output));
        const double wholeCoverage = test::coverage(QImage(whole), test::viewBackground());
        const double pagedCoverage = test::coverage(QImage(paged), test::viewBackground());
        QVERIFY2(wholeCoverage > 0.05, qPrintable(QString::number(wholeCoverage)));
        QVERIFY2(std::abs(pagedCoverage - wholeCoverage) < 0.15 * wholeCoverage,
                 qPrintable(QString("%1 vs %2").arg(pagedCoverage).arg(wholeCoverage)));
    }

    void cliRenderRejectsBadArgumentsAndInputs() {
        QTemporaryDir dir;
        const QString out = dir.filePath("x.png");
        Run run = runProgram(OMICRON_CLI_PATH, {"render", "in.ply", out, "--camera", "sideways"});
        QCOMPARE(run.exitCode, 2);
        QVERIFY2(run.output.contains("--camera"), qPrintable(run.output));
        const QString bad = dir.filePath("bad.ply");
        QFile file(bad);
        QVERIFY(file.open(QIODevice::WriteOnly));
        file.write("ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n");
        file.close();
        run = runProgram(OMICRON_CLI_PATH, {"render", bad, out});
        QCOMPARE(run.exitCode, 1);
        QVERIFY2(run.output.contains("bad.ply"), qPrintable(run.output));
        QVERIFY(!QFile::exists(out));
    }

    void embedExampleStartsAndRenders() {
        const QString bunny = test::sharedDataFile("bunny.ply");
        if (bunny.isEmpty()) {
            QSKIP("../shared/data/bunny.ply is absent");
        }
        QTemporaryDir dir;
        const QString out = dir.filePath("embed.png");
        const Run run = runProgram(OMICRON_EMBED_EXAMPLE_PATH, {bunny, "--snapshot", out});
        QVERIFY2(run.exitCode == 0, qPrintable(run.output));
        const QImage image(out);
        QVERIFY(!image.isNull());
        const double covered = test::coverage(image, test::viewBackground());
        QVERIFY2(covered > 0.03, qPrintable(QString::number(covered)));
    }
};

QTEST_GUILESS_MAIN(tst_RenderProgramsGL)
#include "tst_render_programs_gl.moc"
