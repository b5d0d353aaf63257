#include "parent_sampler.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace omicron {

namespace {

// The picks floor((2j + 1) n / (2 count)) for j = 0, 1, ... without a division per pick (this
// runs for every sampled point of a build): the numerator grows by 2n per pick, so the
// quotient and remainder are carried. Exact for any n < 2^62.
class StratifiedPicks {
public:
    StratifiedPicks(std::uint64_t n, std::uint64_t count)
        : m_divisor(2 * count), m_quotient(n / m_divisor), m_remainder(n % m_divisor),
          m_stepQuotient(2 * n / m_divisor), m_stepRemainder(2 * n % m_divisor) {}

    std::uint64_t position() const { return m_quotient; }
    void next() {
        m_quotient += m_stepQuotient;
        m_remainder += m_stepRemainder;
        if (m_remainder >= m_divisor) {
            m_remainder -= m_divisor;
            ++m_quotient;
        }
    }

private:
    std::uint64_t m_divisor;
    std::uint64_t m_quotient;
    std::uint64_t m_remainder;
    std::uint64_t m_stepQuotient;
    std::uint64_t m_stepRemainder;
};

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
    // Each child takes the picks that fall in its part of the list, with one loop per kind of
    // child (a range or a sample list) so the inner loop is a plain copy.
    StratifiedPicks picks(n, out.size());
    std::size_t j = 0;
    std::uint64_t childStart = 0; // position of the child's first point in the list
    for (const OctreeNode* child : children) {
        const std::uint64_t childEnd = childStart + child->pointCount;
        if (child->holdsRange()) {
            // Unsigned arithmetic wraps, so base + position is exact even when base "< 0".
            const std::uint64_t base = child->coveredBegin - childStart;
            for (; j < out.size() && picks.position() < childEnd; ++j, picks.next()) {
                out[j] = static_cast<std::uint32_t>(base + picks.position());
            }
        } else {
            const std::uint32_t* samples = child->sampleIndices;
            for (; j < out.size() && picks.position() < childEnd; ++j, picks.next()) {
                out[j] = samples[picks.position() - childStart];
            }
        }
        childStart = childEnd;
    }
    assert(j == out.size());
}

void sampleRange(std::uint32_t begin, std::uint32_t count, std::span<std::uint32_t> out) {
    assert(!out.empty() && out.size() <= count);
    StratifiedPicks picks(count, out.size());
    for (std::size_t j = 0; j < out.size(); ++j, picks.next()) {
        out[j] = begin + static_cast<std::uint32_t>(picks.position());
    }
}

} // namespace omicron
