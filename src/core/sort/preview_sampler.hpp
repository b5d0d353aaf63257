// The first pixels of pipeline 1: a uniform random sample of the points read so far
// (reservoir sampling driven by a fixed hash, so the same input gives the same sample on every
// run), taken while the sorter reads, readable from any thread.
#pragma once

#include "points/point_batch.hpp"

#include <cstdint>
#include <mutex>
#include <vector>

namespace omicron {

// A uniform random subsample of the points added so far (positions in the unit cube).
struct PreviewSample {
    std::vector<glm::vec3> positions;
    std::vector<glm::u8vec3> colors; // empty when the cloud has no colour
    std::uint64_t pointsSeen = 0;
    // Drawn from a bounds pre-pass before the final cube is known: positions are in a
    // provisional unit cube (BuildPipeline::preview).
    bool provisional = false;
};

class PreviewSampler {
public:
    PreviewSampler(std::size_t capacity, std::uint64_t seed) : m_capacity(capacity), m_seed(seed) {}

    // Reading thread: `batch` holds points [firstIndex, firstIndex + size) of the input.
    void add(const PointBatch& batch, std::uint64_t firstIndex);

    // Any thread, any time: a copy of the current sample (at most `capacity` points).
    PreviewSample sample() const;

private:
    // The next uniform draw in (0, 1), and in [0, n).
    double uniform();
    std::size_t uniformBelow(std::size_t n);
    // Moves m_next to the next point the reservoir takes.
    void skip();

    std::size_t m_capacity;
    std::uint64_t m_seed;
    std::uint64_t m_draws = 0;
    // Once the reservoir is full: the index of the next point it takes, and Algorithm L's W.
    std::uint64_t m_next = 0;
    double m_w = 1.0;
    mutable std::mutex m_mutex;
    PreviewSample m_sample;
};

} // namespace omicron
