#include "points/asprs_classes.hpp"

#include <array>
#include <cmath>

namespace omicron {

namespace {

struct StandardClass {
    const char* name;
    glm::u8vec3 color;
};

// Classes 0 to 22 as LAS 1.4 defines them.
constexpr std::array<StandardClass, 23> kStandard{{
    {"Never Classified", {160, 160, 160}},
    {"Unclassified", {200, 200, 200}},
    {"Ground", {170, 110, 60}},
    {"Low Vegetation", {170, 230, 110}},
    {"Medium Vegetation", {70, 180, 60}},
    {"High Vegetation", {20, 110, 40}},
    {"Building", {240, 140, 30}},
    {"Low Point (Noise)", {230, 40, 230}},
    {"Model Key-point", {255, 60, 60}},
    {"Water", {40, 110, 240}},
    {"Rail", {120, 80, 160}},
    {"Road Surface", {90, 90, 100}},
    {"Overlap", {255, 230, 60}},
    {"Wire Guard (Shield)", {250, 250, 170}},
    {"Wire Conductor (Phase)", {255, 255, 0}},
    {"Transmission Tower", {200, 60, 40}},
    {"Wire-structure Connector", {210, 210, 90}},
    {"Bridge Deck", {150, 120, 110}},
    {"High Noise", {255, 0, 128}},
    {"Overhead Structure", {100, 190, 190}},
    {"Ignored Ground", {200, 160, 120}},
    {"Snow", {240, 250, 255}},
    {"Temporal Exclusion", {110, 70, 70}},
}};

} // namespace

std::string lasClassName(int classification) {
    if (classification >= 0 && classification < static_cast<int>(kStandard.size())) {
        return kStandard[static_cast<std::size_t>(classification)].name;
    }
    return (classification < 64 ? "Reserved " : "User ") + std::to_string(classification);
}

glm::u8vec3 lasClassColor(int classification) {
    if (classification >= 0 && classification < static_cast<int>(kStandard.size())) {
        return kStandard[static_cast<std::size_t>(classification)].color;
    }
    // Reserved and user classes: distinct hues from a golden-angle walk, so neighbours differ.
    const double hue = std::fmod(classification * 137.508, 360.0) / 60.0;
    const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
    const int sector = static_cast<int>(hue);
    const double rgb[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
    const auto channel = [&](int c) {
        return static_cast<std::uint8_t>(60 + 180 * rgb[sector % 6][c]);
    };
    return {channel(0), channel(1), channel(2)};
}

} // namespace omicron
