// `render`'s name, summary, usage and help, shared by omicron-cli (which starts
// omicron-cli-render for it) and omicron-cli-render (which renders).
#include "commands.hpp"

namespace omicron::cli {

Command renderCommandRunning(int (*run)(const std::vector<std::string>& args)) {
    return {
        "render", "build a cloud's hierarchy and save an image of it (needs a display)",
        "render IN OUT.png [--camera fit|iso|top|bottom|front|back|left|right] [--size WxH] "
        "[--mode points|compute|splats] [--color rgb|normal|height|intensity|level|age|"
        "classification|return-number|gps-time] "
        "[--edl|--no-edl] [--depth N] "
        "[--threshold PX] [--threads T] [--memory-budget SIZE] [--temp-dir DIR]",
        "Runs the pipeline (an unsorted cloud is sorted first; a .oms file is streamed; a .omh\n"
        "hierarchy is loaded), waits for the hierarchy, and renders it with the viewer's\n"
        "CloudView off screen: the front converged at the projection threshold, no point\n"
        "budget.\n\n"
        "  --camera   fit (default: the cloud framed from above at an angle), or a standard view\n"
        "             (top looks down z; front looks along +y)\n"
        "  --size     image size in pixels (default 1280x800)\n"
        "  --mode     compute (default: the points drawn by compute shaders, OpenGL 4.3; GL\n"
        "             points where unavailable), points (GL points) or splats (three-pass\n"
        "             surface splatting)\n"
        "  --color    rgb (default; height where the cloud has no colour), normal, height,\n"
        "             intensity, level (hierarchy level of each node), age (build order),\n"
        "             classification (ASPRS class colours), return-number (1st, 2nd, 3rd,\n"
        "             4th and later), gps-time (a ramp over the GPS times); the LAS ones fall\n"
        "             back to height for clouds without those fields\n"
        "  --edl, --no-edl  eye-dome lighting on or off (default: on for clouds without\n"
        "             colours, where it makes the shape readable)\n"
        "  --depth    hierarchy depth (default 7)\n"
        "  --threshold  front projection threshold in pixels: a node whose cell projects larger\n"
        "             is replaced by its children (default: the viewer's)\n"
        "  --memory-budget SIZE, --temp-dir DIR\n"
        "             as for 'build': a sort beyond the budget runs on disk ($TMPDIR)\n\n"
        "The OpenGL context needs a display: on a headless machine run it under xvfb-run.\n",
        run};
}

} // namespace omicron::cli
