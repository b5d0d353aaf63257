#include "build/parent_sampler.hpp"

#include <algorithm>
#include <array>
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
    // How far position() moves per pick: this or one more.
    std::uint64_t step() const { return m_stepQuotient; }
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

// The held points of an implicit-sample child (OctreeNode::heldPoint) at increasing positions
// k that move by `step` or `step + 1`, as a parent's picks do: floor((2k + 1) n / 2m) is carried
// as a quotient and remainder, so a pick costs additions, not a division (a level of a build
// draws most of its samples from such children).
class ImplicitHeldPoints {
public:
    ImplicitHeldPoints(const OctreeNode& node, std::uint64_t k, std::uint64_t step)
        : m_base(node.coveredBegin), m_divisor(2 * std::uint64_t{node.pointCount}), m_k(k),
          m_step(step) {
        assert(node.holdsImplicitSample());
        const std::uint64_t n = node.coveredCount;
        const std::uint64_t m = node.pointCount;
        m_quotient = stratifiedPick(k, n, m);
        // Exact modulo 2^64, and the true remainder is below the divisor.
        m_remainder = (2 * k + 1) * n - m_quotient * m_divisor;
        // A step of d adds 2dn to the numerator: dn / m whole divisors and 2 (dn % m) over
        // (dn < 2^64: d and n are point counts).
        for (std::uint64_t s = 0; s < 2; ++s) {
            m_stepQuotient[s] = (step + s) * n / m;
            m_stepRemainder[s] = 2 * ((step + s) * n % m);
        }
    }

    std::uint32_t at(std::uint64_t k) {
        if (k != m_k) {
            const std::uint64_t s = k - m_k - m_step;
            assert(s < 2);
            m_k = k;
            m_quotient += m_stepQuotient[s];
            m_remainder += m_stepRemainder[s];
            if (m_remainder >= m_divisor) {
                m_remainder -= m_divisor;
                ++m_quotient;
            }
        }
        return m_base + static_cast<std::uint32_t>(m_quotient);
    }

private:
    std::uint32_t m_base;
    std::uint64_t m_divisor;
    std::uint64_t m_k;
    std::uint64_t m_step;
    std::uint64_t m_quotient;
    std::uint64_t m_remainder;
    std::array<std::uint64_t, 2> m_stepQuotient{};
    std::array<std::uint64_t, 2> m_stepRemainder{};
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
    // child (a range, a sample list, an implicit sample) so the inner loops stay plain.
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
        } else if (child->sampleIndices != nullptr) {
            const std::uint32_t* samples = child->sampleIndices;
            for (; j < out.size() && picks.position() < childEnd; ++j, picks.next()) {
                out[j] = samples[picks.position() - childStart];
            }
        } else if (j < out.size() && picks.position() < childEnd) {
            ImplicitHeldPoints held(*child, picks.position() - childStart, picks.step());
            for (; j < out.size() && picks.position() < childEnd; ++j, picks.next()) {
                out[j] = held.at(picks.position() - childStart);
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
