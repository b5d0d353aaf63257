#include "sort/preview_sampler.hpp"

namespace omicron {

namespace {

__extension__ using Wide = unsigned __int128;

// splitmix64: a fixed, portable hash, so the preview is the same on every machine.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

} // namespace

void PreviewSampler::add(const PointBatch& batch, std::uint64_t firstIndex) {
    if (m_capacity == 0) {
        return;
    }
    const bool hasColor = !batch.colors.empty();
    std::lock_guard lock(m_mutex);
    // Reservoir sampling: point i replaces a random slot with probability capacity / (i + 1).
    for (std::size_t i = 0; i < batch.size(); ++i) {
        const std::uint64_t index = firstIndex + i;
        if (index < m_capacity) {
            m_sample.positions.push_back(batch.positions[i]);
            if (hasColor) {
                m_sample.colors.push_back(batch.colors[i]);
            }
            continue;
        }
        // A uniform slot in [0, index] by a multiply and shift rather than a 64-bit modulo
        // (a division per point cost the reading thread more than the rest of the sample).
        const auto slot =
            static_cast<std::size_t>((static_cast<Wide>(mix(m_seed ^ index)) * (index + 1)) >> 64);
        if (slot < m_capacity) {
            m_sample.positions[slot] = batch.positions[i];
            if (hasColor) {
                m_sample.colors[slot] = batch.colors[i];
            }
        }
    }
    m_sample.pointsSeen = firstIndex + batch.size();
}

PreviewSample PreviewSampler::sample() const {
    std::lock_guard lock(m_mutex);
    return m_sample;
}

} // namespace omicron
