#include "scene/scene_layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace omicron {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Terrestrial-scanner density: full density within kFullDensityRange metres, then falling with
// the square of the range, never below kFarDensity of it (registered scans from several
// stations fill the far field a little).
constexpr double kFullDensityRange = 15.0;
constexpr double kFarDensity = 0.15;
constexpr double kTerrainNearRange = 1.5;     // the scanner's own blind spot
constexpr double kTerrainRangeFraction = 0.7; // terrain points drawn by range, the rest by area

// The statue: a (2, 3) torus knot standing on a pedestal, turned towards the scanner.
constexpr int kKnotP = 2;
constexpr int kKnotQ = 3;
constexpr double kKnotScale = 0.4;
constexpr double kKnotTube = 0.16;
const glm::dvec2 kStatueCentre{8.0, -9.0};

double smoothstep(double edge0, double edge1, double x) {
    const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

glm::dvec3 rgb(glm::u8vec3 color) {
    return glm::dvec3(color);
}

// Rounds to 8 bits after a little per-point variation, as a camera-coloured scan has.
glm::u8vec3 toColor(const glm::dvec3& color, SceneRandom& random, double jitter) {
    glm::u8vec3 result;
    for (int c = 0; c < 3; ++c) {
        const double value = color[c] + (random.uniform() - 0.5) * 2.0 * jitter;
        result[c] = static_cast<std::uint8_t>(std::floor(std::clamp(value, 0.0, 255.0) + 0.5));
    }
    return result;
}

// The unscaled knot curve and its derivative in the knot's own frame.
glm::dvec3 knotCurve(double t) {
    const double r = std::cos(kKnotQ * t) + 2.0;
    return {r * std::cos(kKnotP * t), r * std::sin(kKnotP * t), -std::sin(kKnotQ * t)};
}

glm::dvec3 knotTangent(double t) {
    const double r = std::cos(kKnotQ * t) + 2.0;
    const double dr = -kKnotQ * std::sin(kKnotQ * t);
    return {dr * std::cos(kKnotP * t) - kKnotP * r * std::sin(kKnotP * t),
            dr * std::sin(kKnotP * t) + kKnotP * r * std::cos(kKnotP * t),
            -kKnotQ * std::cos(kKnotQ * t)};
}

// Knot frame -> world directions: the knot's plane stands upright, facing `facing`.
glm::dvec3 knotToWorld(const glm::dvec3& k, const glm::dvec3& across, const glm::dvec3& facing) {
    return k.x * across + k.z * facing + k.y * glm::dvec3(0.0, 0.0, 1.0);
}

} // namespace

double SceneLayout::terrainHeight(double x, double y) {
    return 6.0 * std::sin(0.018 * x + 0.4) * std::cos(0.015 * y - 0.3) +
           3.0 * std::sin(0.041 * x + 0.033 * y + 1.3) +
           1.2 * std::sin(0.093 * x - 0.071 * y + 0.7) + 0.02 * x;
}

glm::dvec2 SceneLayout::terrainGradient(double x, double y) {
    const double a = 0.018 * x + 0.4;
    const double b = 0.015 * y - 0.3;
    const double c = std::cos(0.041 * x + 0.033 * y + 1.3);
    const double d = std::cos(0.093 * x - 0.071 * y + 0.7);
    return {6.0 * 0.018 * std::cos(a) * std::cos(b) + 3.0 * 0.041 * c + 1.2 * 0.093 * d + 0.02,
            -6.0 * 0.015 * std::sin(a) * std::sin(b) + 3.0 * 0.033 * c - 1.2 * 0.071 * d};
}

bool SceneLayout::Footprint::contains(const glm::dvec2& p) const {
    const glm::dvec2 d = p - centre;
    const glm::dvec2 axisY(-axisX.y, axisX.x);
    return std::abs(glm::dot(d, axisX)) < halfSize.x && std::abs(glm::dot(d, axisY)) < halfSize.y;
}

void SceneLayout::PatchSet::add(const Patch& patch) {
    patches.push_back(patch);
    cumulativeArea.push_back((cumulativeArea.empty() ? 0.0 : cumulativeArea.back()) + patch.area);
}

const SceneLayout::Patch& SceneLayout::PatchSet::choose(SceneRandom& random) const {
    const double target = random.uniform() * cumulativeArea.back();
    const auto found = std::upper_bound(cumulativeArea.begin(), cumulativeArea.end(), target);
    const auto index = std::min<std::size_t>(
        static_cast<std::size_t>(found - cumulativeArea.begin()), patches.size() - 1);
    return patches[index];
}

SceneLayout::SceneLayout() {
    m_scanner = {0.0, 0.0, terrainHeight(0.0, 0.0) + 1.6};
    const glm::u8vec3 beige{205, 190, 160}, white{220, 215, 205}, concrete{170, 170, 165};
    const glm::u8vec3 brick{160, 80, 60}, ochre{215, 190, 120}, steel{150, 160, 175};
    addBuilding({45, 32}, {12, 8}, 0.3, 7, true, beige, {150, 60, 45});
    addBuilding({-40, 52}, {10, 7}, -0.2, 6, true, white, {90, 70, 60});
    addBuilding({70, -38}, {15, 10}, 0.1, 18, false, concrete, {110, 110, 110});
    addBuilding({-62, -42}, {9, 9}, 0.7, 24, false, brick, {80, 80, 85});
    addBuilding({12, 88}, {18, 6}, 0.05, 5, true, ochre, {140, 70, 50});
    addBuilding({-98, 38}, {8, 12}, -0.4, 12, false, steel, {100, 100, 105});
    addBuilding({105, 55}, {11, 7}, 0.5, 7, true, {230, 225, 210}, {70, 75, 90});
    addStatue();
    addTrees();
}

void SceneLayout::addBuilding(glm::dvec2 centre, glm::dvec2 halfSize, double angle,
                              double wallHeight, bool gableRoof, glm::u8vec3 wallColor,
                              glm::u8vec3 roofColor) {
    const glm::dvec2 axisX(std::cos(angle), std::sin(angle));
    const glm::dvec2 axisY(-axisX.y, axisX.x);
    const auto world = [&](double x, double y, double z) {
        return glm::dvec3(centre + x * axisX + y * axisY, z);
    };
    const double floorLevel = terrainHeight(centre.x, centre.y);
    // Walls start below the lowest ground of the footprint; underground points are dropped.
    double base = floorLevel;
    for (const double sx : {-1.0, 1.0}) {
        for (const double sy : {-1.0, 1.0}) {
            const glm::dvec3 corner = world(sx * halfSize.x, sy * halfSize.y, 0.0);
            base = std::min(base, terrainHeight(corner.x, corner.y));
        }
    }
    base -= 0.5;
    const double top = floorLevel + wallHeight;
    m_footprints.push_back({centre, axisX, halfSize});

    const auto addFlat = [&](Patch::Shape shape, Patch::Style style, glm::dvec3 origin,
                             glm::dvec3 edgeU, glm::dvec3 edgeV, glm::dvec3 outward,
                             glm::u8vec3 color) {
        Patch patch;
        patch.shape = shape;
        patch.style = style;
        patch.origin = origin;
        patch.edgeU = edgeU;
        patch.edgeV = edgeV;
        glm::dvec3 normal = glm::normalize(glm::cross(edgeU, edgeV));
        patch.normal = glm::dot(normal, outward) < 0.0 ? -normal : normal;
        patch.floorLevel = floorLevel;
        patch.height = wallHeight;
        patch.color = color;
        patch.area =
            glm::length(glm::cross(edgeU, edgeV)) * (shape == Patch::Shape::Triangle ? 0.5 : 1.0);
        m_buildings.add(patch);
    };
    const glm::dvec3 up(0.0, 0.0, 1.0);
    const glm::dvec3 x3(axisX, 0.0), y3(axisY, 0.0);
    const glm::dvec3 wallUp(0.0, 0.0, top - base);
    const double hx = halfSize.x, hy = halfSize.y;
    using Shape = Patch::Shape;
    using Style = Patch::Style;
    addFlat(Shape::Parallelogram, Style::Wall, world(hx, -hy, base), 2 * hy * y3, wallUp, x3,
            wallColor);
    addFlat(Shape::Parallelogram, Style::Wall, world(-hx, hy, base), -2 * hy * y3, wallUp, -x3,
            wallColor);
    addFlat(Shape::Parallelogram, Style::Wall, world(hx, hy, base), -2 * hx * x3, wallUp, y3,
            wallColor);
    addFlat(Shape::Parallelogram, Style::Wall, world(-hx, -hy, base), 2 * hx * x3, wallUp, -y3,
            wallColor);
    if (!gableRoof) {
        addFlat(Shape::Parallelogram, Style::Roof, world(-hx, -hy, top), 2 * hx * x3, 2 * hy * y3,
                up, roofColor);
        return;
    }
    // Ridge along the local x axis, eaves overhanging the walls.
    const double rise = 0.6 * hy;
    const double overhang = 0.4;
    const double eaveDrop = overhang * rise / hy;
    const double run = hy + overhang;
    const glm::dvec3 along = 2 * (hx + overhang) * x3;
    for (const double side : {-1.0, 1.0}) {
        addFlat(Shape::Parallelogram, Style::Roof,
                world(-hx - overhang, side * run, top - eaveDrop), along,
                -side * run * y3 + (rise + eaveDrop) * up, up, roofColor);
        addFlat(Shape::Triangle, Style::Wall, world(side * hx, -hy, top), 2 * hy * y3,
                hy * y3 + rise * up, side * x3, wallColor);
    }
}

void SceneLayout::addStatue() {
    const double floorLevel = terrainHeight(kStatueCentre.x, kStatueCentre.y);
    const double half = 1.2;
    const double base = floorLevel - 0.4;
    const double top = floorLevel + 1.4;
    m_footprints.push_back({kStatueCentre, {1.0, 0.0}, {half, half}});
    const glm::u8vec3 stone{175, 170, 160};
    const auto corner = [&](double sx, double sy, double z) {
        return glm::dvec3(kStatueCentre.x + sx * half, kStatueCentre.y + sy * half, z);
    };
    const glm::dvec3 wallUp(0.0, 0.0, top - base);
    const auto add = [&](glm::dvec3 origin, glm::dvec3 edgeU, glm::dvec3 edgeV, glm::dvec3 normal) {
        Patch patch;
        patch.style = Patch::Style::Stone;
        patch.origin = origin;
        patch.edgeU = edgeU;
        patch.edgeV = edgeV;
        patch.normal = normal;
        patch.color = stone;
        patch.area = glm::length(glm::cross(edgeU, edgeV));
        m_statue.add(patch);
    };
    add(corner(1, -1, base), {0, 2 * half, 0}, wallUp, {1, 0, 0});
    add(corner(-1, -1, base), {0, 2 * half, 0}, wallUp, {-1, 0, 0});
    add(corner(-1, 1, base), {2 * half, 0, 0}, wallUp, {0, 1, 0});
    add(corner(-1, -1, base), {2 * half, 0, 0}, wallUp, {0, -1, 0});
    add(corner(-1, -1, top), {2 * half, 0, 0}, {0, 2 * half, 0}, {0, 0, 1});

    // Arc length and the largest speed of the curve, for area-uniform sampling.
    constexpr int kSteps = 4096;
    double length = 0.0;
    double maxSpeed = 0.0;
    double lowest = 0.0; // of the curve's upright coordinate
    for (int i = 0; i < kSteps; ++i) {
        const double t = 2.0 * kPi * (i + 0.5) / kSteps;
        const double speed = glm::length(knotTangent(t));
        length += speed * 2.0 * kPi / kSteps;
        maxSpeed = std::max(maxSpeed, speed);
        lowest = std::min(lowest, knotCurve(t).y);
    }
    m_knotMaxSpeed = maxSpeed * 1.01;
    const glm::dvec2 towardScanner = glm::normalize(glm::dvec2(m_scanner) - kStatueCentre);
    Patch knot;
    knot.shape = Patch::Shape::Knot;
    knot.style = Patch::Style::Bronze;
    // Resting on the pedestal, the lowest loop half sunk into it.
    knot.origin = glm::dvec3(kStatueCentre, top - lowest * kKnotScale + 0.5 * kKnotTube);
    knot.edgeV = glm::dvec3(towardScanner, 0.0);                     // the knot's thin axis
    knot.edgeU = glm::dvec3(towardScanner.y, -towardScanner.x, 0.0); // across, horizontal
    knot.radius = kKnotTube;
    knot.color = {150, 100, 50};
    knot.area = 2.0 * kPi * kKnotTube * length * kKnotScale;
    m_statue.add(knot);
}

void SceneLayout::addTrees() {
    constexpr int kTrees = 36;
    SceneRandom random(0x7EE5C0DEull); // fixed: the trees are part of the place, not the seed
    const std::array<glm::u8vec3, 5> leafColors{
        {{55, 105, 40}, {75, 120, 45}, {45, 90, 50}, {110, 120, 40}, {170, 110, 40}}};
    std::vector<glm::dvec2> placed;
    while (static_cast<int>(placed.size()) < kTrees) {
        const double range = random.uniform(14.0, 135.0);
        const double angle = random.uniform(0.0, 2.0 * kPi);
        const glm::dvec2 p(range * std::cos(angle), range * std::sin(angle));
        bool clear = std::abs(p.x) < kTerrainHalfSize - 10 && std::abs(p.y) < kTerrainHalfSize - 10;
        clear = clear && !onRoad(p) && !onRoad(p + glm::dvec2(0.0, 4.0)) &&
                !onRoad(p - glm::dvec2(0.0, 4.0));
        for (const Footprint& footprint : m_footprints) {
            Footprint margin = footprint;
            margin.halfSize += glm::dvec2(6.0);
            clear = clear && !margin.contains(p);
        }
        for (const glm::dvec2& other : placed) {
            clear = clear && glm::length(p - other) > 7.0;
        }
        const double trunkRadius = random.uniform(0.18, 0.35);
        const double trunkHeight = random.uniform(2.2, 4.5);
        const double crownRadius = random.uniform(2.0, 4.2);
        const glm::u8vec3 leaves = leafColors[static_cast<std::size_t>(random.uniform() * 5.0)];
        if (!clear) {
            continue;
        }
        placed.push_back(p);
        const double ground = terrainHeight(p.x, p.y);
        const glm::dvec3 crownCentre(p, ground + trunkHeight + 0.8 * crownRadius);

        Patch trunk;
        trunk.shape = Patch::Shape::Cylinder;
        trunk.style = Patch::Style::Bark;
        trunk.origin = glm::dvec3(p, ground - 0.3);
        trunk.radius = trunkRadius;
        trunk.height = crownCentre.z - 0.3 * crownRadius - trunk.origin.z;
        trunk.color = {95, 70, 50};
        trunk.area = 2.0 * kPi * trunkRadius * trunk.height;
        m_trees.add(trunk);

        Patch crown;
        crown.shape = Patch::Shape::Crown;
        crown.style = Patch::Style::Leaves;
        crown.origin = crownCentre;
        crown.radius = crownRadius;
        crown.floorLevel = angle; // a per-tree phase for the crown's bumps
        crown.color = leaves;
        crown.area = 4.0 * kPi * crownRadius * crownRadius;
        m_trees.add(crown);
    }
}

bool SceneLayout::onRoad(const glm::dvec2& p) const {
    // A straight road passing beside the scanner: y = 0.1 x + 3, 5 m wide.
    return std::abs(p.y - 0.1 * p.x - 3.0) / std::sqrt(1.01) < 2.5;
}

double SceneLayout::keepProbability(const glm::dvec3& p) const {
    const double range = glm::length(p - m_scanner);
    const double falloff = std::min(1.0, (kFullDensityRange * kFullDensityRange) / (range * range));
    return kFarDensity + (1.0 - kFarDensity) * falloff;
}

ScenePoint SceneLayout::sample(SceneComponent component, SceneRandom& random) const {
    switch (component) {
    case SceneComponent::Terrain:
        return sampleTerrain(random);
    case SceneComponent::Buildings:
        return sampleSurface(m_buildings, random);
    case SceneComponent::Trees:
        return sampleSurface(m_trees, random);
    case SceneComponent::Statue:
        return sampleSurface(m_statue, random);
    }
    return sampleTerrain(random);
}

ScenePoint SceneLayout::sampleTerrain(SceneRandom& random) const {
    const double farRange = std::sqrt(2.0) * kTerrainHalfSize + glm::length(glm::dvec2(m_scanner));
    for (;;) {
        glm::dvec2 p;
        if (random.uniform() < kTerrainRangeFraction) {
            // Log-uniform range: the density falls with the square of the range.
            const double range =
                kTerrainNearRange *
                std::exp(random.uniform() * std::log(farRange / kTerrainNearRange));
            const double angle = random.uniform(0.0, 2.0 * kPi);
            p = glm::dvec2(m_scanner) + range * glm::dvec2(std::cos(angle), std::sin(angle));
        } else {
            p = {random.uniform(-kTerrainHalfSize, kTerrainHalfSize),
                 random.uniform(-kTerrainHalfSize, kTerrainHalfSize)};
        }
        if (std::abs(p.x) > kTerrainHalfSize || std::abs(p.y) > kTerrainHalfSize) {
            continue;
        }
        if (std::any_of(m_footprints.begin(), m_footprints.end(),
                        [&](const Footprint& footprint) { return footprint.contains(p); })) {
            continue;
        }
        const double height = terrainHeight(p.x, p.y);
        const glm::dvec2 slope = terrainGradient(p.x, p.y);
        ScenePoint point;
        point.position = {p, height};
        point.normal = glm::normalize(glm::dvec3(-slope.x, -slope.y, 1.0));

        // Lush low ground, drier grass higher up, soil patches, rock on steep slopes, a road.
        const double altitude = smoothstep(-12.0, 12.0, height);
        glm::dvec3 color = glm::mix(glm::dvec3(60, 110, 35), glm::dvec3(125, 150, 70), altitude);
        // Incommensurate, domain-warped waves: irregular patches rather than a grid of spots.
        const double soilPattern =
            std::sin(0.047 * p.x + 1.7 * std::sin(0.021 * p.y)) *
                std::sin(0.061 * p.y + 1.3 * std::sin(0.033 * p.x)) +
            0.35 * std::sin(0.13 * p.x + 0.09 * p.y + 2.0 * std::sin(0.05 * p.y));
        color = glm::mix(color, glm::dvec3(125, 100, 70), smoothstep(0.55, 0.85, soilPattern));
        color = glm::mix(color, glm::dvec3(135, 130, 120), smoothstep(0.97, 0.93, point.normal.z));
        if (onRoad(p)) {
            color = glm::dvec3(85, 85, 90);
        }
        point.color = toColor(color, random, 12.0);
        const glm::dvec3 ray = point.position - m_scanner;
        const double range = glm::length(ray);
        point.position += ray / range * (random.noise() * (0.002 + 0.0001 * range));
        return point;
    }
}

ScenePoint SceneLayout::sampleSurface(const PatchSet& set, SceneRandom& random) const {
    for (;;) {
        const Patch& patch = set.choose(random);
        ScenePoint point = samplePatch(patch, random);
        const bool mayBeUnderground =
            patch.style != Patch::Style::Roof && patch.style != Patch::Style::Bronze;
        if (mayBeUnderground &&
            point.position.z < terrainHeight(point.position.x, point.position.y)) {
            continue;
        }
        if (random.uniform() >= keepProbability(point.position)) {
            continue;
        }
        const glm::dvec3 ray = point.position - m_scanner;
        const double range = glm::length(ray);
        point.position += ray / range * (random.noise() * (0.002 + 0.0001 * range));
        return point;
    }
}

ScenePoint SceneLayout::samplePatch(const Patch& patch, SceneRandom& random) const {
    ScenePoint point;
    double s = random.uniform();
    double t = random.uniform();
    glm::dvec3 color = rgb(patch.color);
    double jitter = 10.0;
    switch (patch.shape) {
    case Patch::Shape::Triangle:
        if (s + t > 1.0) {
            s = 1.0 - s;
            t = 1.0 - t;
        }
        [[fallthrough]];
    case Patch::Shape::Parallelogram:
        point.position = patch.origin + s * patch.edgeU + t * patch.edgeV;
        point.normal = patch.normal;
        break;
    case Patch::Shape::Cylinder: {
        const double angle = 2.0 * kPi * s;
        const glm::dvec3 radial(std::cos(angle), std::sin(angle), 0.0);
        point.position = patch.origin + patch.radius * radial + glm::dvec3(0, 0, t * patch.height);
        point.normal = radial;
        color *= 0.8 + 0.2 * std::sin(40.0 * angle + 3.0 * t); // bark ridges
        break;
    }
    case Patch::Shape::Knot:
        return sampleKnot(patch, random);
    case Patch::Shape::Crown: {
        // Leaves fill the outer part of a bumpy sphere; normals scatter like leaves do.
        const double z = 2.0 * s - 1.0;
        const double angle = 2.0 * kPi * t;
        const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
        const glm::dvec3 direction(ring * std::cos(angle), ring * std::sin(angle), z);
        const double bump = 1.0 + 0.12 * std::sin(3.0 * angle + patch.floorLevel) *
                                      std::sin(4.0 * z + patch.floorLevel);
        const double depth = 1.0 - 0.3 * random.uniform() * random.uniform();
        point.position = patch.origin + direction * (patch.radius * bump * depth);
        const glm::dvec3 scatter(random.noise(), random.noise(), random.noise());
        point.normal = glm::normalize(direction + 0.35 * scatter);
        color *= 0.7 + 0.3 * depth + 0.08 * z;
        jitter = 18.0;
        break;
    }
    }
    if (patch.style == Patch::Style::Wall) {
        const double along = s * glm::length(patch.edgeU);
        const double level = point.position.z - patch.floorLevel;
        const double storey = std::fmod(level, 3.0);
        const double column = std::fmod(along, 2.6);
        const bool window = level > 0.0 && level < patch.height - 0.5 && storey > 0.9 &&
                            storey < 2.1 && column > 0.8 && column < 1.9 && along > 1.0 &&
                            along < glm::length(patch.edgeU) - 1.0;
        color =
            window ? glm::dvec3(55, 65, 80) : color * (0.85 + 0.15 * std::min(1.0, level / 1.5));
        jitter = window ? 5.0 : 10.0;
    } else if (patch.style == Patch::Style::Roof) {
        const double slope = t * glm::length(patch.edgeV);
        color *= std::fmod(slope, 0.35) < 0.06 ? 0.75 : 1.0; // tile rows
    } else if (patch.style == Patch::Style::Stone) {
        jitter = 14.0;
    }
    point.color = toColor(color, random, jitter);
    return point;
}

ScenePoint SceneLayout::sampleKnot(const Patch& patch, SceneRandom& random) const {
    const glm::dvec3 across = patch.edgeU;
    const glm::dvec3 facing = patch.edgeV;
    double t = 0.0;
    glm::dvec3 tangent;
    do { // accept t in proportion to the curve's speed: uniform over the tube's area
        t = random.uniform(0.0, 2.0 * kPi);
        tangent = knotToWorld(knotTangent(t), across, facing);
    } while (random.uniform() * m_knotMaxSpeed > glm::length(tangent));
    const glm::dvec3 centre = patch.origin + kKnotScale * knotToWorld(knotCurve(t), across, facing);
    const glm::dvec3 unitTangent = glm::normalize(tangent);
    const glm::dvec3 helper =
        std::abs(unitTangent.z) > 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 0.0, 1.0);
    const glm::dvec3 sideA = glm::normalize(glm::cross(unitTangent, helper));
    const glm::dvec3 sideB = glm::cross(unitTangent, sideA);
    const double angle = random.uniform(0.0, 2.0 * kPi);
    ScenePoint point;
    point.normal = std::cos(angle) * sideA + std::sin(angle) * sideB;
    point.position = centre + patch.radius * point.normal;
    // Bronze with green patina where rain runs: more on upward faces, in streaks.
    const double patina =
        std::clamp(0.25 + 0.45 * point.normal.z + 0.25 * std::sin(5.0 * t + 2.0 * angle), 0.0, 1.0);
    const glm::dvec3 color = glm::mix(rgb(patch.color), glm::dvec3(70, 135, 105), patina);
    point.color = toColor(color, random, 10.0);
    return point;
}

} // namespace omicron
