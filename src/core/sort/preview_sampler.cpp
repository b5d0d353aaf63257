#include "sort/preview_sampler.hpp"

#include <algorithm>
#include <cmath>

namespace omicron {

namespace {

__extension__ using Wide = unsigned __int128;

// splitmix64: a fixed, portable hash of the draw's number, so the sample does not depend on
// the machine's random sources.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

// Skips this long or longer only when W has become tiny: no cloud gets there.
constexpr double kLongestSkip = 0x1p62;

} // namespace

double PreviewSampler::uniform() {
    // 53 random bits, offset by half a step: never 0, never 1.
    return (static_cast<double>(mix(m_seed ^ m_draws++) >> 11) + 0.5) * 0x1p-53;
}

std::size_t PreviewSampler::uniformBelow(std::size_t n) {
    // A multiply and shift rather than a 64-bit modulo.
    return static_cast<std::size_t>((static_cast<Wide>(mix(m_seed ^ m_draws++)) * n) >> 64);
}

// Li's Algorithm L: W is the largest of the reservoir's random keys, and the number of points
// passed over before the next one taken is geometric in 1 - W.
void PreviewSampler::skip() {
    const double gap = std::floor(std::log(uniform()) / std::log1p(-m_w));
    m_next += static_cast<std::uint64_t>(std::min(gap, kLongestSkip)) + 1;
    m_w *= std::exp(std::log(uniform()) / static_cast<double>(m_capacity));
}

void PreviewSampler::add(const PointBatch& batch, std::uint64_t firstIndex) {
    if (m_capacity == 0) {
        return;
    }
    const bool hasColor = !batch.colors.empty();
    const std::uint64_t end = firstIndex + batch.size();
    std::lock_guard lock(m_mutex);
    // The first points fill the reservoir.
    std::uint64_t index = firstIndex;
    for (; index < end && index < m_capacity; ++index) {
        m_sample.positions.push_back(batch.positions[index - firstIndex]);
        if (hasColor) {
            m_sample.colors.push_back(batch.colors[index - firstIndex]);
        }
    }
    if (index < m_capacity) {
        m_sample.pointsSeen = end; // still filling
        return;
    }
    if (firstIndex < m_capacity) { // this batch filled it
        m_w = std::exp(std::log(uniform()) / static_cast<double>(m_capacity));
        m_next = m_capacity - 1;
        skip();
    }
    // Then point i is taken with probability capacity / (i + 1), into a random slot: jumping
    // from one taken point to the next costs a few draws per taken point (about
    // capacity * ln(points / capacity) of them) instead of a hash per point read, which was
    // 2 % of a LAS build's CPU time, on the sorter's thread that bounds the read phase.
    while (m_next < end) {
        const std::size_t i = static_cast<std::size_t>(m_next - firstIndex);
        const std::size_t slot = uniformBelow(m_capacity);
        m_sample.positions[slot] = batch.positions[i];
        if (hasColor) {
            m_sample.colors[slot] = batch.colors[i];
        }
        skip();
    }
    m_sample.pointsSeen = end;
}

PreviewSample PreviewSampler::sample() const {
    std::lock_guard lock(m_mutex);
    return m_sample;
}

} // namespace omicron
