#include "parent_sampler.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace omicron {

namespace {
// (2j + 1) n can exceed 64 bits when one node holds billions of points.
__extension__ using Wide = unsigned __int128;

std::uint64_t pick(std::uint64_t j, std::uint64_t n, std::uint64_t count) {
    if (n < (std::uint64_t{1} << 31)) { // the usual case fits 64 bits: j < count <= n
        return ((2 * j + 1) * n) / (2 * count);
    }
    return static_cast<std::uint64_t>((Wide{2 * j + 1} * n) / (Wide{2} * count));
}
} // namespace

std::uint32_t sampleSize(std::uint64_t childrenPoints, double ratio) {
    const double scaled = std::round(ratio * static_cast<double>(childrenPoints));
    const auto size = static_cast<std::uint64_t>(std::max(1.0, scaled));
    return static_cast<std::uint32_t>(std::min(size, std::max<std::uint64_t>(childrenPoints, 1)));
}

void sampleChildren(std::span<const OctreeNode* const> children, std::span<std::uint32_t> out) {
    std::uint64_t n = 0;
    for (const OctreeNode* child : children) {
        n += child->pointCount;
    }
    assert(!out.empty() && out.size() <= n);
    std::size_t child = 0;
    std::uint64_t childStart = 0; // position of children[child]'s first point in the list
    for (std::size_t j = 0; j < out.size(); ++j) {
        const std::uint64_t position = pick(j, n, out.size());
        while (position >= childStart + children[child]->pointCount) {
            childStart += children[child]->pointCount;
            ++child;
        }
        out[j] = children[child]->heldPoint(static_cast<std::uint32_t>(position - childStart));
    }
}

void sampleRange(std::uint32_t begin, std::uint32_t count, std::span<std::uint32_t> out) {
    assert(!out.empty() && out.size() <= count);
    for (std::size_t j = 0; j < out.size(); ++j) {
        out[j] = begin + static_cast<std::uint32_t>(pick(j, count, out.size()));
    }
}

float parentSplatScale(std::span<const OctreeNode* const> children, std::uint32_t kept) {
    double area = 0.0;
    for (const OctreeNode* child : children) {
        area += static_cast<double>(child->pointCount) * child->splatScale * child->splatScale;
    }
    return static_cast<float>(std::sqrt(area / static_cast<double>(kept)));
}

} // namespace omicron
