#include "io/source_normalizer.hpp"

#include <cstdio>

namespace omicron {

void SourceNormalizer::throwOutOfBounds(const std::string& path, InputLocation where,
                                        const glm::dvec3& source) const {
    char detail[512];
    std::snprintf(detail, sizeof detail,
                  "point (%.6f, %.6f, %.6f) lies outside the bounding box [%.6f, %.6f, %.6f] .. "
                  "[%.6f, %.6f, %.6f] the cloud was opened with (the header's bounds are wrong)",
                  source.x, source.y, source.z, m_bounds.min.x, m_bounds.min.y, m_bounds.min.z,
                  m_bounds.max.x, m_bounds.max.y, m_bounds.max.z);
    throw InputError(InputErrorKind::OutOfBounds, path, where, detail);
}

} // namespace omicron
