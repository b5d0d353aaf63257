#include "io/ply/ply_float_records.hpp"

#include "io/ply/ply_values.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace omicron {

namespace {

float loadFloat(const std::uint8_t* bytes) {
    float value;
    std::memcpy(&value, bytes, sizeof value);
    return value;
}

double loadDouble(const std::uint8_t* bytes) {
    double value;
    std::memcpy(&value, bytes, sizeof value);
    return value;
}

// Floats in increasing order map to increasing integers, so a binary search can walk them.
std::int32_t floatOrder(float value) {
    const std::int32_t bits = std::bit_cast<std::int32_t>(value);
    return bits >= 0 ? bits : std::numeric_limits<std::int32_t>::min() - bits;
}

float orderedFloat(std::int32_t order) {
    return std::bit_cast<float>(order >= 0 ? order
                                           : std::numeric_limits<std::int32_t>::min() - order);
}

// Walking from `inside` (which passes) towards `outside`, the last float that still passes;
// `passes` must hold on an interval of floats. Binary search over the float order.
template <typename Passes> float searchEdge(float inside, float outside, Passes passes) {
    if (passes(outside)) {
        return outside;
    }
    std::int64_t good = floatOrder(inside);
    std::int64_t bad = floatOrder(outside);
    while (good - bad > 1 || bad - good > 1) {
        const std::int64_t middle = good + (bad - good) / 2;
        if (passes(orderedFloat(static_cast<std::int32_t>(middle)))) {
            good = middle;
        } else {
            bad = middle;
        }
    }
    return orderedFloat(static_cast<std::int32_t>(good));
}

} // namespace

FloatUnitTransform::FloatUnitTransform(const SourceNormalizer& normalizer,
                                       const CubeTransform& cube, const Bounds& bounds,
                                       const glm::dvec3& pointOffset)
    : offset(pointOffset), origin(cube.origin), inverseEdge(1.0 / cube.edge) {
    // Per axis, the stored floats whose source coordinate passes inBounds form an interval
    // (double(f) + offset is monotonic); find its ends by binary search from a float inside.
    // An axis with no such float gets an empty box, which sends every point to exact code.
    const glm::dvec3 center = (bounds.min + bounds.max) * 0.5;
    const float largest = std::numeric_limits<float>::max();
    for (int axis = 0; axis < 3; ++axis) {
        const auto passes = [&](float stored) {
            glm::dvec3 probe = center;
            probe[axis] = static_cast<double>(stored) + offset[axis];
            return normalizer.inBounds(probe);
        };
        low[axis] = largest;
        high[axis] = -largest;
        if (bounds.empty()) {
            continue;
        }
        // The centre rounded to float may miss a bounds interval narrower than a float step.
        const float rounded = static_cast<float>(center[axis] - offset[axis]);
        const float candidates[] = {rounded, std::nextafter(rounded, largest),
                                    std::nextafter(rounded, -largest)};
        const float* inside = std::find_if(std::begin(candidates), std::end(candidates),
                                           [&](float f) { return std::isfinite(f) && passes(f); });
        if (inside == std::end(candidates)) {
            continue;
        }
        low[axis] = searchEdge(*inside, -largest, passes);
        high[axis] = searchEdge(*inside, largest, passes);
    }
}

namespace {

void extendScalar(const std::uint8_t* records, std::size_t count, const FloatRecordLayout& layout,
                  FloatBox& box) {
    std::array<float, 3> low = box.low;
    std::array<float, 3> high = box.high;
    std::uint64_t finite = 0;
    for (std::size_t r = 0; r < count; ++r) {
        const std::uint8_t* record = records + r * layout.recordBytes;
        const float x = loadFloat(record + layout.position[0]);
        const float y = loadFloat(record + layout.position[1]);
        const float z = loadFloat(record + layout.position[2]);
        if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) {
            continue;
        }
        ++finite;
        low = {std::min(low[0], x), std::min(low[1], y), std::min(low[2], z)};
        high = {std::max(high[0], x), std::max(high[1], y), std::max(high[2], z)};
    }
    box.low = low;
    box.high = high;
    box.finite += finite;
}

// Where a record's optional attributes are and where they go: locals of the conversion loops
// (byte stores may alias anything, which would reload a struct's fields per point).
struct AttributeCopy {
    std::array<std::size_t, 3> normalAt{};
    std::array<std::size_t, 3> colorAt{};
    std::size_t intensityAt = 0;
    glm::vec3* normals = nullptr;
    glm::u8vec3* colors = nullptr;
    std::uint16_t* intensities = nullptr;
};

using Intensity = FloatRecordLayout::Intensity;
using Color = FloatRecordLayout::Color;
using Normals = FloatRecordLayout::Normals;

// A ushort colour channel as 8 bits: plyColorChannel's round(v / 257) in integers (v / 257 is
// never within 1/514 of a half, so the two agree for every v).
inline std::uint8_t colorByte(const std::uint8_t* at) {
    std::uint16_t v;
    std::memcpy(&v, at, sizeof v);
    return static_cast<std::uint8_t>((2u * v + 257u) / 514u);
}

// The optional float or double normal, uchar, ushort or float colour and ushort or float
// intensity of record r, shared by both conversions. Only present arrays are indexed:
// arithmetic on an absent array's null pointer is undefined behaviour (found by fuzz_ply under
// UBSan).
template <Normals kNormals, Color kColor, Intensity kIntensity>
inline void copyOptionalAttributes(const std::uint8_t* record, std::size_t r,
                                   const AttributeCopy& copy) {
    if constexpr (kNormals == Normals::Float) {
        copy.normals[r] =
            glm::vec3(loadFloat(record + copy.normalAt[0]), loadFloat(record + copy.normalAt[1]),
                      loadFloat(record + copy.normalAt[2]));
    } else if constexpr (kNormals == Normals::Double) {
        copy.normals[r] = glm::vec3(glm::dvec3(loadDouble(record + copy.normalAt[0]),
                                               loadDouble(record + copy.normalAt[1]),
                                               loadDouble(record + copy.normalAt[2])));
    }
    if constexpr (kColor == Color::UChar) {
        copy.colors[r] =
            glm::u8vec3(record[copy.colorAt[0]], record[copy.colorAt[1]], record[copy.colorAt[2]]);
    } else if constexpr (kColor == Color::UShort) {
        copy.colors[r] =
            glm::u8vec3(colorByte(record + copy.colorAt[0]), colorByte(record + copy.colorAt[1]),
                        colorByte(record + copy.colorAt[2]));
    } else if constexpr (kColor == Color::Float) {
        copy.colors[r] = glm::u8vec3(
            plyColorChannel(loadFloat(record + copy.colorAt[0]), PlyScalarType::Float32),
            plyColorChannel(loadFloat(record + copy.colorAt[1]), PlyScalarType::Float32),
            plyColorChannel(loadFloat(record + copy.colorAt[2]), PlyScalarType::Float32));
    }
    if constexpr (kIntensity == Intensity::UShort) {
        std::memcpy(&copy.intensities[r], record + copy.intensityAt, sizeof(std::uint16_t));
    } else if constexpr (kIntensity == Intensity::Float) {
        copy.intensities[r] = plyIntensity(loadFloat(record + copy.intensityAt));
    }
}

AttributeCopy attributeCopy(const FloatRecordLayout& layout, const FloatRecordOutputs& outputs) {
    return {layout.normal,   layout.color,   layout.intensity,
            outputs.normals, outputs.colors, outputs.intensities};
}

template <Normals kNormals, Color kColor, Intensity kIntensity>
std::size_t convertScalar(const std::uint8_t* records, std::size_t count,
                          const FloatRecordLayout& layout, const FloatUnitTransform& transform,
                          const FloatRecordOutputs& outputs) {
    // Locals: the colour byte stores may alias anything, which would reload these per point.
    const std::size_t stride = layout.recordBytes;
    const std::array<std::size_t, 3> positionAt = layout.position;
    const AttributeCopy copy = attributeCopy(layout, outputs);
    const std::array<float, 3> low = transform.low;
    const std::array<float, 3> high = transform.high;
    const glm::dvec3 offset = transform.offset;
    const glm::dvec3 origin = transform.origin;
    const double inverseEdge = transform.inverseEdge;
    glm::vec3* const positions = outputs.positions;
    for (std::size_t r = 0; r < count; ++r) {
        const std::uint8_t* record = records + r * stride;
        const float x = loadFloat(record + positionAt[0]);
        const float y = loadFloat(record + positionAt[1]);
        const float z = loadFloat(record + positionAt[2]);
        if (!(x >= low[0] && x <= high[0] && y >= low[1] && y <= high[1] && z >= low[2] &&
              z <= high[2])) {
            return r;
        }
        const glm::dvec3 source(static_cast<double>(x) + offset.x,
                                static_cast<double>(y) + offset.y,
                                static_cast<double>(z) + offset.z);
        positions[r] = glm::vec3((source - origin) * inverseEdge);
        copyOptionalAttributes<kNormals, kColor, kIntensity>(record, r, copy);
    }
    return count;
}

#if defined(__SSE2__)

// Extends low/high by one record's x y z unless a coordinate is NaN or infinite.
inline void extendLanes(const std::uint8_t* xyzBytes, __m128 keepXyz, __m128& low, __m128& high,
                        std::uint64_t& finite) {
    // The fourth lane holds the next field's bytes: zeroed, it cannot be a slow denormal.
    const __m128 xyz = _mm_and_ps(_mm_loadu_ps(reinterpret_cast<const float*>(xyzBytes)), keepXyz);
    // v - v is 0 for finite values and NaN for NaN and infinities.
    const int finiteLanes = _mm_movemask_ps(_mm_cmpeq_ps(_mm_sub_ps(xyz, xyz), _mm_setzero_ps()));
    if ((finiteLanes & 7) == 7) [[likely]] {
        ++finite;
        low = _mm_min_ps(xyz, low);
        high = _mm_max_ps(xyz, high);
    }
}

void extendSse2(const std::uint8_t* records, std::size_t count, const FloatRecordLayout& layout,
                FloatBox& box) {
    // Two accumulator pairs (even and odd records) halve the min/max dependency chains.
    __m128 lowEven = _mm_setr_ps(box.low[0], box.low[1], box.low[2], 0.0f);
    __m128 highEven = _mm_setr_ps(box.high[0], box.high[1], box.high[2], 0.0f);
    __m128 lowOdd = lowEven;
    __m128 highOdd = highEven;
    const __m128 keepXyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    std::uint64_t finite = 0;
    const std::size_t stride = layout.recordBytes;
    const std::uint8_t* xyz = records + layout.position[0];
    std::size_t r = 0;
    for (; r + 1 < count; r += 2) {
        extendLanes(xyz + r * stride, keepXyz, lowEven, highEven, finite);
        extendLanes(xyz + (r + 1) * stride, keepXyz, lowOdd, highOdd, finite);
    }
    if (r < count) {
        extendLanes(xyz + r * stride, keepXyz, lowEven, highEven, finite);
    }
    alignas(16) float low[4];
    alignas(16) float high[4];
    _mm_store_ps(low, _mm_min_ps(lowEven, lowOdd));
    _mm_store_ps(high, _mm_max_ps(highEven, highOdd));
    for (int axis = 0; axis < 3; ++axis) {
        box.low[axis] = low[axis];
        box.high[axis] = high[axis];
    }
    box.finite += finite;
}

template <Normals kNormals, Color kColor, Intensity kIntensity>
std::size_t convertSse2(const std::uint8_t* records, std::size_t count,
                        const FloatRecordLayout& layout, const FloatUnitTransform& transform,
                        const FloatRecordOutputs& outputs) {
    const __m128 low = _mm_setr_ps(transform.low[0], transform.low[1], transform.low[2], 0.0f);
    const __m128 high = _mm_setr_ps(transform.high[0], transform.high[1], transform.high[2], 0.0f);
    const __m128 keepXyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    const __m128d offsetXy = _mm_setr_pd(transform.offset.x, transform.offset.y);
    const __m128d offsetZ = _mm_setr_pd(transform.offset.z, 0.0);
    const __m128d originXy = _mm_setr_pd(transform.origin.x, transform.origin.y);
    const __m128d originZ = _mm_setr_pd(transform.origin.z, 0.0);
    const __m128d inverseEdge = _mm_set1_pd(transform.inverseEdge);
    // Locals: the colour byte stores may alias anything, which would reload `layout` per point.
    const std::size_t stride = layout.recordBytes;
    const std::size_t xyzAt = layout.position[0];
    const AttributeCopy copy = attributeCopy(layout, outputs);
    glm::vec3* const positions = outputs.positions;
    for (std::size_t r = 0; r < count; ++r) {
        const std::uint8_t* record = records + r * stride;
        // The fourth lane holds the next field's bytes: zeroed, it cannot be a slow denormal.
        const __m128 xyz =
            _mm_and_ps(_mm_loadu_ps(reinterpret_cast<const float*>(record + xyzAt)), keepXyz);
        const __m128 inside = _mm_and_ps(_mm_cmpge_ps(xyz, low), _mm_cmple_ps(xyz, high));
        if ((_mm_movemask_ps(inside) & 7) != 7) {
            return r;
        }
        // The same double operations, in the same order, as SourceNormalizer::toUnit.
        __m128d xy = _mm_cvtps_pd(xyz);
        __m128d z = _mm_cvtps_pd(_mm_movehl_ps(xyz, xyz));
        xy = _mm_mul_pd(_mm_sub_pd(_mm_add_pd(xy, offsetXy), originXy), inverseEdge);
        z = _mm_mul_pd(_mm_sub_pd(_mm_add_pd(z, offsetZ), originZ), inverseEdge);
        const __m128 unit = _mm_movelh_ps(_mm_cvtpd_ps(xy), _mm_cvtpd_ps(z));
        float* position = &positions[r].x;
        _mm_storel_pi(reinterpret_cast<__m64*>(position), unit);
        _mm_store_ss(position + 2, _mm_movehl_ps(unit, unit));
        copyOptionalAttributes<kNormals, kColor, kIntensity>(record, r, copy);
    }
    return count;
}

#endif

template <Normals kNormals, Color kColor, Intensity kIntensity>
std::size_t convert(const std::uint8_t* records, std::size_t count, const FloatRecordLayout& layout,
                    const FloatUnitTransform& transform, const FloatRecordOutputs& outputs) {
#if defined(__SSE2__)
    if (layout.adjacentPosition()) {
        return convertSse2<kNormals, kColor, kIntensity>(records, count, layout, transform,
                                                         outputs);
    }
#endif
    return convertScalar<kNormals, kColor, kIntensity>(records, count, layout, transform, outputs);
}

// Double x y z, as PDAL writes them: source = x + offset and the normalizer's own checks,
// point by point, as the general path does (no float prefilter box to find).
template <Normals kNormals, Color kColor, Intensity kIntensity>
std::size_t convertDoubles(const std::uint8_t* records, std::size_t count,
                           const FloatRecordLayout& layout, const SourceNormalizer& normalizer,
                           const glm::dvec3& offset, const FloatRecordOutputs& outputs) {
    const std::size_t stride = layout.recordBytes;
    const std::array<std::size_t, 3> positionAt = layout.position;
    const AttributeCopy copy = attributeCopy(layout, outputs);
    glm::vec3* const positions = outputs.positions;
    for (std::size_t r = 0; r < count; ++r) {
        const std::uint8_t* record = records + r * stride;
        const glm::dvec3 source(loadDouble(record + positionAt[0]) + offset.x,
                                loadDouble(record + positionAt[1]) + offset.y,
                                loadDouble(record + positionAt[2]) + offset.z);
        if (!normalizer.inBounds(source)) { // also false for NaN
            return r;
        }
        positions[r] = normalizer.toUnit(source);
        copyOptionalAttributes<kNormals, kColor, kIntensity>(record, r, copy);
    }
    return count;
}

// Calls convert.template operator()<kNormals, kColor, kIntensity>() for the layout's
// optional attributes: one instantiation of a conversion loop per combination.
template <typename Convert>
std::size_t forLayoutAttributes(const FloatRecordLayout& layout, const Convert& convert) {
    const auto withIntensity = [&]<Normals kNormals, Color kColor>() -> std::size_t {
        switch (layout.intensityType) {
        case Intensity::UShort:
            return convert.template operator()<kNormals, kColor, Intensity::UShort>();
        case Intensity::Float:
            return convert.template operator()<kNormals, kColor, Intensity::Float>();
        case Intensity::None:
            break;
        }
        return convert.template operator()<kNormals, kColor, Intensity::None>();
    };
    const auto withColor = [&]<Normals kNormals>() -> std::size_t {
        switch (layout.colorType) {
        case Color::UChar:
            return withIntensity.template operator()<kNormals, Color::UChar>();
        case Color::UShort:
            return withIntensity.template operator()<kNormals, Color::UShort>();
        case Color::Float:
            return withIntensity.template operator()<kNormals, Color::Float>();
        case Color::None:
            break;
        }
        return withIntensity.template operator()<kNormals, Color::None>();
    };
    switch (layout.normalType) {
    case Normals::Float:
        return withColor.template operator()<Normals::Float>();
    case Normals::Double:
        return withColor.template operator()<Normals::Double>();
    case Normals::None:
        break;
    }
    return withColor.template operator()<Normals::None>();
}

} // namespace

void extendFloatBox(const std::uint8_t* records, std::size_t count, const FloatRecordLayout& layout,
                    FloatBox& box) {
#if defined(__SSE2__)
    if (layout.adjacentPosition()) {
        extendSse2(records, count, layout, box);
        return;
    }
#endif
    extendScalar(records, count, layout, box);
}

std::size_t convertFloatRecords(const std::uint8_t* records, std::size_t count,
                                const FloatRecordLayout& layout,
                                const FloatUnitTransform& transform,
                                const FloatRecordOutputs& outputs) {
    return forLayoutAttributes(layout, [&]<Normals kNormals, Color kColor, Intensity kIntensity>() {
        return convert<kNormals, kColor, kIntensity>(records, count, layout, transform, outputs);
    });
}

glm::dvec3 sourcePosition(const std::uint8_t* record, const FloatRecordLayout& layout,
                          const glm::dvec3& offset) {
    glm::dvec3 source;
    for (int axis = 0; axis < 3; ++axis) {
        const std::uint8_t* stored = record + layout.position[axis];
        source[axis] =
            (layout.doublePositions ? loadDouble(stored) : loadFloat(stored)) + offset[axis];
    }
    return source;
}

void extendDoubleBounds(const std::uint8_t* records, std::size_t count,
                        const FloatRecordLayout& layout, const glm::dvec3& offset,
                        DoubleBounds& bounds) {
    Bounds box = bounds.box;
    std::uint64_t finite = 0;
    for (std::size_t r = 0; r < count; ++r) {
        const glm::dvec3 source = sourcePosition(records + r * layout.recordBytes, layout, offset);
        if (SourceNormalizer::isFinite(source)) {
            ++finite;
            box.extend(source);
        }
    }
    bounds.box = box;
    bounds.finite += finite;
}

std::size_t convertDoubleRecords(const std::uint8_t* records, std::size_t count,
                                 const FloatRecordLayout& layout,
                                 const SourceNormalizer& normalizer, const glm::dvec3& offset,
                                 const FloatRecordOutputs& outputs) {
    return forLayoutAttributes(layout, [&]<Normals kNormals, Color kColor, Intensity kIntensity>() {
        return convertDoubles<kNormals, kColor, kIntensity>(records, count, layout, normalizer,
                                                            offset, outputs);
    });
}

} // namespace omicron
