#include "formats/oms_format.hpp"

#include "points/sorted_cloud.hpp"

#include <stdexcept>

// Header-only xxHash (Debian's libxxhash-dev): inlined here, no library to link.
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace omicron::oms {

std::uint64_t headerChecksum(const std::uint8_t* headerBytes) {
    return XXH64(headerBytes, header::kChecksum, 0);
}

UniformColumns uniformColumnsOf(const SortedCloud& cloud) {
    UniformColumns uniform;
    if (cloud.uniformIntensities()) {
        uniform.bits |= kUniformIntensityBit;
        uniform.intensity = cloud.intensities()[0];
    }
    const std::size_t lasBytes = cloud.attributes().lasBytes();
    if (cloud.uniformLasColumn() && lasBytes <= kMaxUniformLasBytes) {
        uniform.bits |= kUniformLasBit;
        uniform.lasRecord.assign(cloud.lasRecord(0), cloud.lasRecord(0) + lasBytes);
    }
    return uniform;
}

RecordLayout storedRecordLayout(AttributeSet attributes, const UniformColumns& uniform) {
    return RecordLayout::of(attributes).without(uniform.intensityUniform(), uniform.lasUniform());
}

struct PayloadChecksum::State {
    XXH3_state_t xxh3;
};

PayloadChecksum::PayloadChecksum() : m_state(std::make_unique<State>()) {
    if (XXH3_64bits_reset(&m_state->xxh3) != XXH_OK) {
        throw std::runtime_error("XXH3_64bits_reset failed");
    }
}

PayloadChecksum::~PayloadChecksum() = default;

void PayloadChecksum::update(const void* bytes, std::size_t count) {
    XXH3_64bits_update(&m_state->xxh3, bytes, count);
}

std::uint64_t PayloadChecksum::digest() const {
    return XXH3_64bits_digest(&m_state->xxh3);
}

} // namespace omicron::oms
