// The sums a splat estimate needs of one fine cell's points (count, coordinates, their squares
// and cross products), accumulated in float lanes relative to the cell's first point and handed
// over as double moments relative to the node's corner (SplatScratch::Moments).
//
// Summed point by point in double relative to the node's corner, the moments were most of an
// estimate's time: three conversions, three subtractions and ten scalar additions per point.
// Relative to a point of the cell itself the values are as small as the cell, so floats keep
// them exact enough, and three SSE lanes take x, y and z at once (one subtraction, three
// additions, two multiplications and a shuffle per point). A run is closed into the double
// moments every kMaxRun points, so that a cell holding millions of points (coincident ones,
// or a node at the deepest level) never sums that many floats.
#pragma once

#include "build/splat_estimator.hpp"

#include <cstdint>
#include <glm/vec3.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace omicron {

class CellSums {
public:
    static constexpr std::uint32_t kMaxRun = 4096;

    // Moments come out relative to `origin` (the node's corner).
    explicit CellSums(const glm::dvec3& origin) : m_origin(origin) {}

    // Starts a new cell whose first point is `first`.
    void start(const glm::vec3& first) {
        m_closed = {};
        open(first);
    }

    void add(const glm::vec3& p) {
        if (m_count == kMaxRun) {
            m_closed.add(runMoments());
            open(p);
        }
        ++m_count;
#if defined(__SSE2__)
        const __m128 r = _mm_sub_ps(_mm_setr_ps(p.x, p.y, p.z, 0.0f), m_first);
        m_sum = _mm_add_ps(m_sum, r);
        m_squares = _mm_add_ps(m_squares, _mm_mul_ps(r, r));
        // (x, y, z) times (y, z, x): xy, yz, zx.
        m_cross = _mm_add_ps(m_cross, _mm_mul_ps(r, _mm_shuffle_ps(r, r, _MM_SHUFFLE(3, 0, 2, 1))));
#else
        const glm::vec3 r = p - m_firstPoint;
        m_sum += r;
        m_squares += r * r;
        m_cross += r * glm::vec3(r.y, r.z, r.x);
#endif
    }

    // The cell's moments so far.
    SplatScratch::Moments moments() const {
        SplatScratch::Moments all = m_closed;
        all.add(runMoments());
        return all;
    }

private:
    void open(const glm::vec3& first) {
        m_count = 0;
        m_firstPoint = first;
#if defined(__SSE2__)
        m_first = _mm_setr_ps(first.x, first.y, first.z, 0.0f);
        m_sum = m_squares = m_cross = _mm_setzero_ps();
#else
        m_sum = m_squares = m_cross = glm::vec3(0.0f);
#endif
    }

    // The open run's moments relative to the origin: for q = r + d, with d the run's first
    // point relative to the origin, sum q = sum r + n d and sum q_i q_j = sum r_i r_j
    // + d_i sum r_j + d_j sum r_i + n d_i d_j.
    SplatScratch::Moments runMoments() const {
        float sum[4], squares[4], cross[4];
#if defined(__SSE2__)
        _mm_storeu_ps(sum, m_sum);
        _mm_storeu_ps(squares, m_squares);
        _mm_storeu_ps(cross, m_cross);
#else
        for (int axis = 0; axis < 3; ++axis) {
            sum[axis] = m_sum[axis];
            squares[axis] = m_squares[axis];
            cross[axis] = m_cross[axis];
        }
#endif
        const double n = m_count;
        const glm::dvec3 d = glm::dvec3(m_firstPoint) - m_origin;
        const glm::dvec3 s(sum[0], sum[1], sum[2]);
        SplatScratch::Moments m;
        m.count = n;
        m.sx = s.x + n * d.x;
        m.sy = s.y + n * d.y;
        m.sz = s.z + n * d.z;
        m.sxx = squares[0] + 2.0 * d.x * s.x + n * d.x * d.x;
        m.syy = squares[1] + 2.0 * d.y * s.y + n * d.y * d.y;
        m.szz = squares[2] + 2.0 * d.z * s.z + n * d.z * d.z;
        m.sxy = cross[0] + d.x * s.y + d.y * s.x + n * d.x * d.y;
        m.syz = cross[1] + d.y * s.z + d.z * s.y + n * d.y * d.z;
        m.sxz = cross[2] + d.z * s.x + d.x * s.z + n * d.z * d.x;
        return m;
    }

    glm::dvec3 m_origin;
    SplatScratch::Moments m_closed; // the cell's runs closed so far
    std::uint32_t m_count = 0;      // points of the open run
    glm::vec3 m_firstPoint{0.0f};
#if defined(__SSE2__)
    __m128 m_first = _mm_setzero_ps(); // m_firstPoint in lanes, for add()
    __m128 m_sum = _mm_setzero_ps();
    __m128 m_squares = _mm_setzero_ps();
    __m128 m_cross = _mm_setzero_ps();
#else
    glm::vec3 m_sum{0.0f}, m_squares{0.0f}, m_cross{0.0f};
#endif
};

} // namespace omicron
