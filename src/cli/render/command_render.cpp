// omicron-cli render, run by omicron-cli-render: the full pipeline (unsorted cloud or .oms ->
// builder), then one image of the finished hierarchy through the same CloudView the
// application shows, without a visible window. Needs a display for the OpenGL context (under
// CI: xvfb-run).
#include "cli_args.hpp"
#include "cloud_view.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/input_error.hpp"
#include "pipeline/build_pipeline.hpp"

#include <QApplication>
#include <QBuffer>
#include <QImage>
#include <cstdio>
#include <cstdlib>
#include <tbb/global_control.h>

namespace omicron::cli {

namespace {

struct CameraChoice {
    const char* name;
    bool fit;
    StandardView view;
};

constexpr CameraChoice kCameras[] = {
    {"fit", true, StandardView::Iso},      {"iso", false, StandardView::Iso},
    {"top", false, StandardView::Top},     {"bottom", false, StandardView::Bottom},
    {"front", false, StandardView::Front}, {"back", false, StandardView::Back},
    {"left", false, StandardView::Left},   {"right", false, StandardView::Right},
};

constexpr std::pair<const char*, RenderMode> kModes[] = {
    {"points", RenderMode::Points},
    {"compute", RenderMode::ComputePoints},
    {"splats", RenderMode::Splats},
};

constexpr std::pair<const char*, ColorMode> kColors[] = {
    {"rgb", ColorMode::Rgb},
    {"normal", ColorMode::Normal},
    {"height", ColorMode::Height},
    {"intensity", ColorMode::Intensity},
    {"level", ColorMode::Level},
    {"age", ColorMode::BuildAge},
    {"classification", ColorMode::Classification},
    {"return-number", ColorMode::ReturnNumber},
    {"gps-time", ColorMode::GpsTime},
};

QSize parseSize(const std::string& text) {
    const auto x = text.find('x');
    if (x == std::string::npos) {
        throw UsageError("--size takes WIDTHxHEIGHT, e.g. 1280x800, found '" + text + "'");
    }
    const auto width = parseInteger(text.substr(0, x), "size", 16, 8192);
    const auto height = parseInteger(text.substr(x + 1), "size", 16, 8192);
    return QSize(static_cast<int>(width), static_cast<int>(height));
}

// Pipelines 1, 2 or 3 by the file's kind: the same driver as `build` and the application.
std::shared_ptr<const Hierarchy> loadOrBuildHierarchy(const std::string& path,
                                                      const BuildOptions& options,
                                                      const MemoryOptions& memory) {
    BuildPipeline pipeline;
    runInterruptibly(pipeline, path,
                     {options, kDefaultSortChunks, PointStorage::Exact, memory.budgetBytes,
                      memory.tempDir,
                      /*preview=*/false});
    return pipeline.hierarchy();
}

int runRender(const std::vector<std::string>& args) {
    const ParsedArgs parsed = parseArgs(args, withOptions({{"camera", true},
                                                           {"size", true},
                                                           {"mode", true},
                                                           {"color", true},
                                                           {"depth", true},
                                                           {"threshold", true},
                                                           {"threads", true},
                                                           {"edl", false},
                                                           {"no-edl", false}},
                                                          kMemoryOptionSpecs));
    if (parsed.help) {
        printCommandHelp(renderCommand());
        return 0;
    }
    if (parsed.positionals.size() != 2) {
        throw UsageError("expected IN and OUT.png, found " +
                         std::to_string(parsed.positionals.size()) + " arguments");
    }
    const CameraChoice* camera = &kCameras[0];
    if (const auto name = parsed.value("camera")) {
        camera = nullptr;
        for (const CameraChoice& choice : kCameras) {
            camera = *name == choice.name ? &choice : camera;
        }
        if (camera == nullptr) {
            throw UsageError("--camera takes fit, iso, top, bottom, front, back, left or right, "
                             "found '" +
                             *name + "'");
        }
    }
    RenderSettings settings;
    settings.showAxes = false;
    settings.showCutBoundary = false;
    settings.pointBudget = 0; // an image of everything the threshold asks for
    if (const auto mode = parsed.value("mode")) {
        bool known = false;
        for (const auto& [name, value] : kModes) {
            if (*mode == name) {
                settings.mode = value;
                known = true;
            }
        }
        if (!known) {
            throw UsageError("--mode takes points, compute or splats, found '" + *mode + "'");
        }
    }
    if (const auto color = parsed.value("color")) {
        bool known = false;
        for (const auto& [name, value] : kColors) {
            if (*color == name) {
                settings.color = value;
                known = true;
            }
        }
        if (!known) {
            throw UsageError("--color takes rgb, normal, height, intensity, level, age, "
                             "classification, return-number or gps-time, found '" +
                             *color + "'");
        }
    }
    if (parsed.flag("edl") && parsed.flag("no-edl")) {
        throw UsageError("--edl and --no-edl contradict each other: give one");
    }
    settings.edl = parsed.flag("edl")      ? EdlMode::On
                   : parsed.flag("no-edl") ? EdlMode::Off
                                           : EdlMode::Auto;
    if (const auto threshold = parsed.value("threshold")) {
        settings.projectionThresholdPx =
            static_cast<double>(parseInteger(*threshold, "threshold", 1, 100000));
    }
    const QSize size = parseSize(parsed.value("size").value_or("1280x800"));
    BuildOptions options;
    if (const auto depth = parsed.value("depth")) {
        options.maxLevel = static_cast<int>(parseInteger(*depth, "depth", 1, morton::kMaxLevel));
    }
    const int threads = threadsOption(parsed);
    options.threads = threads;
    tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(threads));
    const std::string& inPath = parsed.positionals[0];
    const std::string& outPath = parsed.positionals[1];
    const MemoryOptions memory = memoryOptions(parsed, "");

    if (std::getenv("DISPLAY") == nullptr && std::getenv("WAYLAND_DISPLAY") == nullptr) {
        throw OutputError(outPath + ": rendering needs a display for its OpenGL context; none is "
                                    "set (headless machines: run under xvfb-run)");
    }
    const auto hierarchy = loadOrBuildHierarchy(inPath, options, memory);

    int argc = 1;
    char programName[] = "omicron-cli";
    char* argv[] = {programName, nullptr};
    QApplication app(argc, argv);
    CloudView view;
    view.setRenderSettings(settings);
    view.setHierarchy(hierarchy);
    if (!camera->fit) {
        view.setStandardView(camera->view);
    }
    const QImage image = view.renderImage(size);
    if (image.isNull()) {
        throw OutputError(outPath +
                          ": no OpenGL 3.3 context: " + view.glErrorString().toStdString());
    }
    QByteArray png;
    QBuffer buffer(&png);
    buffer.open(QIODevice::WriteOnly);
    if (!image.save(&buffer, "PNG")) {
        throw OutputError(outPath + ": cannot encode the image as PNG");
    }
    AtomicFileWriter writer(outPath); // temporary file + rename: no partial PNG is ever left
    writer.write(png.constData(), static_cast<std::size_t>(png.size()));
    writer.commit();
    const FrameStats stats = view.lastFrameStats();
    std::printf("rendered %zu of %zu points (%zu nodes) at %dx%d into %s\n", stats.pointsDrawn,
                stats.pointsTotal, stats.nodesDrawn, size.width(), size.height(), outPath.c_str());
    if (const NodeResidency* paged = hierarchy->residency()) {
        const ResidencyStats residency = paged->stats();
        std::printf("points paged in on demand: %llu nodes loaded (%.1f MiB read), %.1f MiB "
                    "resident of a %.1f MiB budget, %llu evicted\n",
                    static_cast<unsigned long long>(residency.loads),
                    static_cast<double>(residency.bytesRead) / (1 << 20),
                    static_cast<double>(residency.residentBytes) / (1 << 20),
                    static_cast<double>(residency.budgetBytes) / (1 << 20),
                    static_cast<unsigned long long>(residency.evictions));
        if (residency.failedNodes > 0) {
            std::fprintf(stderr,
                         "omicron-cli: %llu nodes could not be read, their parents were "
                         "drawn instead; the first: %s\n",
                         static_cast<unsigned long long>(residency.failedNodes),
                         residency.firstError.c_str());
        }
    }
    return 0;
}

} // namespace

const Command& renderCommand() {
    static const Command command = renderCommandRunning(runRender);
    return command;
}

} // namespace omicron::cli
