// The fixed layout of the procedural scene and how to draw one point on it: rolling terrain
// around a terrestrial scanner, box buildings with windows and flat or gable roofs, trees and a
// torus-knot statue on a pedestal. Metres, z up, the scanner near the origin.
//
// The layout itself never changes (the seed only changes which points are drawn), so every
// seed shows the same place. Points are drawn on the surfaces with a density that falls with
// the distance from the scanner, like a real scan, and with a few millimetres of range noise.
#pragma once

#include "scene/scene_random.hpp"

#include <glm/gtc/type_precision.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vector>

namespace omicron {

enum class SceneComponent : std::uint8_t { Terrain, Buildings, Trees, Statue };

struct ScenePoint {
    glm::dvec3 position; // metres
    glm::dvec3 normal;   // unit length
    glm::u8vec3 color;
};

class SceneLayout {
public:
    SceneLayout();

    // One point of `component`, drawn with `random` (a varying number of draws).
    ScenePoint sample(SceneComponent component, SceneRandom& random) const;

    // Height of the terrain at (x, y), and its gradient.
    static double terrainHeight(double x, double y);
    static glm::dvec2 terrainGradient(double x, double y);

    static constexpr double kTerrainHalfSize = 150.0;

    // A surface piece the samplers choose by area.
    struct Patch {
        enum class Shape : std::uint8_t { Parallelogram, Triangle, Cylinder, Crown, Knot };
        enum class Style : std::uint8_t { Wall, Roof, Stone, Bark, Leaves, Bronze };
        Shape shape = Shape::Parallelogram;
        Style style = Style::Wall;
        glm::dvec3 origin{0.0}; // corner; cylinder: centre of the base; crown/knot: centre
        glm::dvec3 edgeU{0.0};  // parallelogram/triangle edges from `origin`
        glm::dvec3 edgeV{0.0};
        glm::dvec3 normal{0.0}; // parallelogram/triangle
        double radius = 0.0;    // cylinder, crown, knot tube
        double height = 0.0;    // cylinder
        double floorLevel = 0.0; // walls: ground-floor height, for the window rows
        glm::u8vec3 color{0};
        double area = 0.0;
    };

private:
    struct Footprint { // a building's or the pedestal's ground rectangle: no terrain inside
        glm::dvec2 centre;
        glm::dvec2 axisX;
        glm::dvec2 halfSize;
        bool contains(const glm::dvec2& p) const;
    };
    struct PatchSet {
        std::vector<Patch> patches;
        std::vector<double> cumulativeArea;
        void add(const Patch& patch);
        const Patch& choose(SceneRandom& random) const;
    };

    void addBuilding(glm::dvec2 centre, glm::dvec2 halfSize, double angle, double wallHeight,
                     bool gableRoof, glm::u8vec3 wallColor, glm::u8vec3 roofColor);
    void addTrees();
    void addStatue();

    ScenePoint sampleTerrain(SceneRandom& random) const;
    ScenePoint sampleSurface(const PatchSet& set, SceneRandom& random) const;
    ScenePoint samplePatch(const Patch& patch, SceneRandom& random) const;
    ScenePoint sampleKnot(const Patch& patch, SceneRandom& random) const;
    bool onRoad(const glm::dvec2& p) const;
    double keepProbability(const glm::dvec3& p) const;

    glm::dvec3 m_scanner{0.0};
    std::vector<Footprint> m_footprints;
    PatchSet m_buildings;
    PatchSet m_trees;
    PatchSet m_statue;
    double m_knotMaxSpeed = 1.0;
};

} // namespace omicron
