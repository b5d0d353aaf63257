// Value types of the CloudView API: what to draw and how, and what a frame cost.
#pragma once

#include "points/asprs_classes.hpp"
#include "points/clip_box.hpp"
#include "points/morton.hpp"

#include <QMetaType>
#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>

namespace omicron {

enum class RenderMode {
    Points, // one GL point per point, screen size from the splat radius
    Splats, // surface splats: visibility, Gaussian accumulation and normalisation passes
    // The same points as Points, drawn by compute shaders (OpenGL 4.3; GL points where a
    // context has no compute shaders). Faster than GL points on Mesa llvmpipe, hence the
    // default (render_bench, autzen_south, 1280x800, 1M budget: 54.5 vs 103.4 ms a frame).
    ComputePoints,
};

// Keep the numbers in sync with shaders/color.glsl. The LAS modes fall back to Height where
// the cloud has no LAS column (Classification, ReturnNumber) or no GPS times (GpsTime).
enum class ColorMode {
    Rgb,
    Normal,
    Height,
    Intensity,
    Level,
    BuildAge,
    Classification, // ASPRS class colours (lasClassColor)
    ReturnNumber,   // 1st, 2nd, 3rd, 4th and later returns in four colours
    GpsTime,        // a ramp over the GPS times of the points uploaded so far
};

// Eye-dome lighting: Auto shades clouds without colours of their own (where the colour is a
// height ramp and the shape is hard to read), as Potree does.
enum class EdlMode { Auto, On, Off };

enum class StandardView { Top, Bottom, Front, Back, Left, Right, Iso };

struct RenderSettings {
    RenderMode mode = RenderMode::ComputePoints;
    ColorMode color = ColorMode::Rgb; // falls back to Height where the cloud has no colour
    float pointSizeScale = 1.0f;      // multiplies the splat radius on screen
    // Front: a node whose cell projects larger than this branches, smaller prunes. 16 px draws
    // the lion (342k points) with 40k points at 500x500 and no visible loss of detail.
    double projectionThresholdPx = 16.0;
    // Most points drawn per frame: Mesa llvmpipe draws ~3M points/s, so 1M keeps it usable.
    std::size_t pointBudget = 1'000'000;
    double frontBudgetMs = 2.0;                     // front evaluation CPU time per frame
    std::size_t uploadBudgetBytes = 32u << 20;      // GPU uploads per frame
    std::size_t gpuMemoryBudgetBytes = 1024u << 20; // node buffers kept on the GPU
    bool showBoundingBox = true;                    // the cloud's bounding box
    bool showOctreeCells = false;                   // wireframe of the front's node cells
    bool showCutBoundary = true;                    // highlight of the roots of the oblique cut
    bool showAxes = true;                           // axis gizmo in the corner
    bool showScaleBar = true; // a round length at the pivot's depth, bottom right
    // An arrow to +y (grid north) top right, for georeferenced clouds (the file names a
    // coordinate system, or coordinates of 10^4 units or more: a projected system, where +y
    // is north).
    bool showNorthArrow = true;
    EdlMode edl = EdlMode::Auto;
    float edlStrength = 1.0f; // how dark an edge one log2 step of depth deep gets
    float edlRadiusPx = 1.4f; // how far the neighbours it compares with are
    // Only the points inside this box (source coordinates: the file's units) are drawn, and
    // octree cells wholly outside it are culled by the front. None: everything.
    std::optional<ClipBox> clip;
    // Points whose ASPRS class (LAS classification) is set here are not drawn, in any render
    // mode (CloudView::setClassVisible edits it). Clouds without classes are class 0.
    std::bitset<kLasClassCount> hiddenClasses;
    friend bool operator==(const RenderSettings&, const RenderSettings&) = default;
};

struct FrameStats {
    double frameMs = 0.0; // CPU time of paintGL (front, uploads, draw calls)
    double frontMs = 0.0; // front evaluation alone
    double fps = 0.0;     // frames per second over the last second
    std::size_t frontNodes = 0;
    // frontNodes by level 0..morton::kMaxLevel (placeholders at their leaf's level).
    std::array<std::size_t, morton::kMaxLevel + 1> frontNodesPerLevel{};
    std::size_t placeholders = 0;
    std::size_t nodesDrawn = 0;
    std::size_t pointsDrawn = 0;
    std::size_t pointsTotal = 0; // points of the cloud (input)
    std::size_t uploads = 0;     // node buffers uploaded this frame
    std::size_t gpuBytes = 0;    // node buffers resident on the GPU
    bool showingPreview = false;
    bool eyeDomeLighting = false; // the frame was shaded with EDL
    // A hierarchy whose points are paged in on demand (a .omh beyond the memory budget):
    // node loads asked for and not done, before or after this frame's front evaluation (the
    // view keeps drawing while any is), and the points in memory against the budget.
    bool pagedPoints = false;
    std::uint64_t pendingLoads = 0;
    std::uint64_t pagedResidentBytes = 0;
    std::uint64_t pagedBudgetBytes = 0;
    // The paper's front insertion delay: leaves of the builder's insertion log whose points
    // this frame drew for the first time (by their own node or an ancestor standing for them),
    // and the time from the builder publishing each of them to this frame.
    std::size_t leavesFirstDrawn = 0;
    double leafDrawDelayMedianMs = 0.0;
    double leafDrawDelayMaxMs = 0.0;
};

// A point of the cloud under the cursor (CloudView::pickCloudPoint): one the frame drew.
struct PickedPoint {
    glm::dvec3 source{0.0};       // in the file's coordinates and units (offsets included)
    glm::vec3 unitPosition{0.0f}; // in the hierarchy's unit cube
    int level = 0;                // of the node that drew it
    std::uint32_t cloudIndex = 0;
    bool hasColor = false;
    glm::u8vec3 color{0};
    bool hasIntensity = false;
    std::uint16_t intensity = 0;
    // The LAS fields (points/las_fields.hpp), where the cloud has its LAS column.
    bool hasLas = false;
    std::uint8_t classification = 0;
    std::uint8_t returnNumber = 0;
    std::uint8_t numberOfReturns = 0;
    std::uint8_t lasFlags = 0; // las_flag bits: synthetic, key-point, withheld, overlap, ...
    std::uint8_t userData = 0;
    std::uint16_t pointSourceId = 0;
    double scanAngleDegrees = 0.0;
    bool hasGpsTime = false;
    double gpsTime = 0.0;
};

} // namespace omicron

Q_DECLARE_METATYPE(omicron::RenderSettings)
Q_DECLARE_METATYPE(omicron::PickedPoint)
Q_DECLARE_METATYPE(omicron::FrameStats)
