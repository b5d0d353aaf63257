#include "formats/oms_record_decoder.hpp"

#include "hex_text.hpp"
#include "io/input_error.hpp"
#include "io/raw_bytes.hpp"
#include "points/morton_batch.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <span>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace omicron {

OmsRecordDecoder::OmsRecordDecoder(const oms::RecordLayout& layout, AttributeSet attributes,
                                   std::string path)
    : m_layout(layout), m_attributes(attributes), m_path(std::move(path)) {}

morton::Code OmsRecordDecoder::decode(const std::uint8_t* block, std::size_t count,
                                      std::size_t first, morton::Code previousCode,
                                      const SortedCloud::StagedRange& out) {
    const std::size_t grains = (count + kGrainPoints - 1) / kGrainPoints;
    m_checks.assign(grains, GrainCheck{});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grains, 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t g = range.begin(); g != range.end(); ++g) {
                              const std::size_t begin = g * kGrainPoints;
                              const std::size_t end = std::min(count, begin + kGrainPoints);
                              m_checks[g] = decodeGrain(block, begin, end, out);
                          }
                      });
    return throwFirstBadRecord(first, previousCode);
}

OmsRecordDecoder::GrainCheck
OmsRecordDecoder::decodeGrain(const std::uint8_t* block, std::size_t begin, std::size_t end,
                              const SortedCloud::StagedRange& out) const {
    GrainCheck check;
    const std::size_t recordBytes = m_layout.bytes;
    // Positions first: the codes of the finite prefix are then computed at once.
    std::size_t finiteEnd = end;
    const std::uint8_t* record = block + begin * recordBytes;
    for (std::size_t at = begin; at < end; ++at, record += recordBytes) {
        const auto p = loadRaw<glm::vec3>(record);
        out.positions[at] = p;
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            finiteEnd = at;
            break;
        }
    }
    std::array<morton::Code, kGrainPoints> codes;
    const std::size_t finite = finiteEnd - begin;
    morton::encodeUnitBatch(out.positions.subspan(begin, finite), std::span(codes.data(), finite));
    if (finite != 0) {
        check.first = codes[0];
    }
    for (std::size_t i = 1; i < finite; ++i) {
        if (codes[i] < codes[i - 1]) {
            check.bad = begin + i;
            check.badCode = codes[i];
            check.codeBefore = codes[i - 1];
            return check;
        }
    }
    if (finiteEnd != end) {
        check.bad = finiteEnd;
        check.nonFinite = true;
        return check;
    }
    check.last = codes[finite - 1];
    copyAttributes(block, begin, end, out);
    return check;
}

void OmsRecordDecoder::copyAttributes(const std::uint8_t* block, std::size_t begin, std::size_t end,
                                      const SortedCloud::StagedRange& out) const {
    const std::size_t recordBytes = m_layout.bytes;
    const std::size_t lasBytes = m_attributes.lasBytes();
    const std::uint8_t* record = block + begin * recordBytes;
    for (std::size_t at = begin; at < end; ++at, record += recordBytes) {
        if (m_attributes.has(Attribute::Normal)) {
            out.normals[at] = loadRaw<glm::vec3>(record + m_layout.normalOffset);
        }
        if (m_attributes.has(Attribute::Color)) {
            out.colors[at] = loadRaw<glm::u8vec3>(record + m_layout.colorOffset);
        }
        // A uniform column is stored once already: not staged (an empty span).
        if (!out.intensities.empty()) {
            out.intensities[at] = loadRaw<std::uint16_t>(record + m_layout.intensityOffset);
        }
        if (!out.las.empty()) {
            std::memcpy(out.las.data() + at * lasBytes, record + m_layout.lasOffset, lasBytes);
        }
    }
}

morton::Code OmsRecordDecoder::throwFirstBadRecord(std::size_t first,
                                                   morton::Code previousCode) const {
    const auto byteOf = [&](std::size_t record) {
        return oms::kHeaderBytes + std::uint64_t{record} * m_layout.bytes;
    };
    const auto outOfOrder = [&](std::size_t record, morton::Code code, morton::Code before) {
        const std::uint64_t at = byteOf(record);
        return InputError(InputErrorKind::MalformedValue, m_path, InputLocation::byte(at),
                          "record " + std::to_string(record) + " at byte " + std::to_string(at) +
                              " is out of Morton order: the file is not sorted (its code " +
                              hexText(code) + " is below the previous record's " + hexText(before) +
                              ")");
    };
    for (std::size_t g = 0; g < m_checks.size(); ++g) {
        const GrainCheck& check = m_checks[g];
        const std::size_t grainBegin = g * kGrainPoints;
        const bool firstIsFinite = !(check.nonFinite && check.bad == grainBegin);
        if (firstIsFinite && check.first < previousCode) {
            throw outOfOrder(first + grainBegin, check.first, previousCode);
        }
        if (check.bad == GrainCheck::kNone) {
            previousCode = check.last;
            continue;
        }
        const std::size_t record = first + check.bad;
        if (check.nonFinite) {
            throw InputError(InputErrorKind::MalformedValue, m_path,
                             InputLocation::byte(byteOf(record)),
                             "record " + std::to_string(record) +
                                 ": expected a finite position in the unit cube");
        }
        throw outOfOrder(record, check.badCode, check.codeBefore);
    }
    return previousCode;
}

} // namespace omicron
