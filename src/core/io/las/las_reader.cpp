#include "io/las/las_reader.hpp"

#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/las/las_extra_bytes.hpp"
#include "io/las/las_file_records.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_point_fields.hpp"
#include "io/laz/laz_records.hpp"
#include "io/pre_pass_monitor.hpp"
#include "io/raw_bytes.hpp"
#include "io/source_normalizer.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

static_assert(std::endian::native == std::endian::little,
              "LAS records are little-endian and are decoded with memcpy loads");

namespace omicron {

namespace {

// How many records, spread evenly over the file, decide the colour depth.
constexpr std::uint64_t kColorSampleRecords = 4096;
// Records a parse slice holds at least: some 60 microseconds of work (about 8 ns a record
// here), far more than handing a slice to another thread costs.
constexpr std::size_t kParseSlicePoints = 8192;

// LAS stores colour in 16-bit fields, but many writers put 8-bit values there unscaled.
enum class ColorDepth {
    None,
    EightBitIn16BitFields, // every sampled channel <= 255: taken as is
    SixteenBit,            // some sampled channel > 255: scaled by 1/257, rounded
};

// Turns LAS point records into points, whatever their source (plain records, or LAZ chunks
// decoded by io/laz).
class LasReader final : public PointReader {
public:
    LasReader(const std::string& path, const las::Header& header,
              std::unique_ptr<LasRecordSource> records, CloudFormat format,
              const OpenOptions& options)
        : m_header(header), m_records(std::move(records)), m_fileBytes(fileSize(path)) {
        m_info.path = path;
        m_info.format = format;
        m_info.pointCount = m_header.pointCount;
        m_info.sourceOffset = m_header.offset;
        m_info.attributes = las::attributesOfFormat(m_header.pointFormat, m_header.recordLength);
        if (las::describesExtraBytes(m_header.extraBytesDescriptors,
                                     m_info.attributes.extraBytes())) {
            m_info.lasExtraBytesDescriptors = m_header.extraBytesDescriptors;
        }
        m_info.lasProjectionRecords = m_header.projectionRecords;
        if (las::formatHasColor(m_header.pointFormat)) {
            m_colorOffset = las::colorOffset(m_header.pointFormat);
            m_colorDepth = sampleColorDepth();
        }
        if (options.knownBounds) {
            m_info.sourceBounds = *options.knownBounds;
        } else if (m_header.hasUsableBounds()) {
            m_info.sourceBounds = m_header.declaredBounds;
            m_info.boundsFromHeader = true;
        } else {
            m_info.sourceBounds = boundsPrePass(options);
        }
        m_info.cube = CubeTransform::fromBounds(m_info.sourceBounds);
        m_info.formatDetail = describeFormat();
        if (options.onHierarchyPreview) {
            offerHierarchyPreview(options);
        }
    }

    ReadSummary read(const BatchConsumer& consumer, const ReadOptions& options) override;

private:
    static std::uint64_t fileSize(const std::string& path) {
        std::error_code error;
        const std::uintmax_t size = std::filesystem::file_size(path, error);
        return error ? 0 : static_cast<std::uint64_t>(size);
    }

    glm::dvec3 sourcePosition(const std::uint8_t* record) const {
        return sourcePosition(record, m_header.scale, m_header.offset);
    }

    // The record's X, Y and Z integers in source units.
    static glm::dvec3 sourcePosition(const std::uint8_t* record, const glm::dvec3& scale,
                                     const glm::dvec3& offset) {
        return glm::dvec3(loadRaw<std::int32_t>(record), loadRaw<std::int32_t>(record + 4),
                          loadRaw<std::int32_t>(record + 8)) *
                   scale +
               offset;
    }

    glm::u8vec3 color(const std::uint8_t* record) const {
        return color(record + m_colorOffset, m_colorDepth == ColorDepth::SixteenBit);
    }

    // `rgb`: the record's three 16-bit channels.
    static glm::u8vec3 color(const std::uint8_t* rgb, bool sixteenBit) {
        const int red = loadRaw<std::uint16_t>(rgb);
        const int green = loadRaw<std::uint16_t>(rgb + 2);
        const int blue = loadRaw<std::uint16_t>(rgb + 4);
        if (sixteenBit) {
            return {(red + 128) / 257, (green + 128) / 257, (blue + 128) / 257};
        }
        // A channel above 255 that the sample missed is clamped rather than wrapped.
        return {std::min(red, 255), std::min(green, 255), std::min(blue, 255)};
    }

    void offerHierarchyPreview(const OpenOptions& options) {
        std::vector<glm::dvec3> positions;
        std::vector<glm::u8vec3> colors;
        const bool hasColor = m_colorDepth != ColorDepth::None;
        m_records->hierarchyPreview(kPrePassSamplePoints, [&](const std::uint8_t* record) {
            positions.push_back(sourcePosition(record));
            if (hasColor) {
                colors.push_back(color(record));
            }
        });
        if (!positions.empty()) {
            options.onHierarchyPreview(positions, colors);
        }
    }

    // Only when the header's bounds are unusable (NaN, min > max): one pass over the records.
    Bounds boundsPrePass(const OpenOptions& options) {
        Bounds bounds;
        PrePassMonitor monitor(options, m_info.path, m_fileBytes, m_header.pointCount);
        monitor.advance(m_header.pointDataOffset);
        m_records->forEachBlock([&](const LasRecordBlock& block) {
            for (std::uint64_t i = 0; i < block.count; ++i) {
                const glm::dvec3 source = sourcePosition(block.records + i * m_header.recordLength);
                bounds.extend(source);
                if (monitor.samples(block.firstIndex + i)) {
                    monitor.offer(source);
                }
            }
            return monitor.reached(block.endByte);
        });
        monitor.finish();
        return bounds;
    }

    // The heuristic: read the colour of up to kColorSampleRecords records spread over the
    // file; if every sampled channel is <= 255 the file holds 8-bit values in its 16-bit
    // fields, otherwise true 16-bit values. A sample keeps opening cheap on huge files.
    ColorDepth sampleColorDepth() {
        bool sixteenBit = false;
        m_colorSamples =
            m_records->sampleRecords(kColorSampleRecords, [&](const std::uint8_t* record) {
                for (int channel = 0; channel < 3; ++channel) {
                    if (loadRaw<std::uint16_t>(record + m_colorOffset + 2 * channel) > 255) {
                        sixteenBit = true;
                    }
                }
            });
        return sixteenBit ? ColorDepth::SixteenBit : ColorDepth::EightBitIn16BitFields;
    }

    std::string describeFormat() const {
        std::string detail = "LAS 1." + std::to_string(m_header.versionMinor) + ", point format " +
                             std::to_string(m_header.pointFormat) + ", " +
                             std::to_string(m_header.recordLength) + "-byte records";
        const int extraBytes =
            m_header.recordLength - las::minimumRecordLength(m_header.pointFormat);
        if (extraBytes > 0) {
            detail += " (" + std::to_string(extraBytes) + " extra bytes)";
        }
        if (las::formatHasWaveform(m_header.pointFormat)) {
            detail += ", waveform packets ignored";
        }
        const std::string storage = m_records->describe();
        if (!storage.empty()) {
            detail += ", " + storage;
        }
        const std::string sampled =
            " (judged from " + std::to_string(m_colorSamples) + " sampled records)";
        if (m_colorDepth == ColorDepth::EightBitIn16BitFields) {
            detail += ", 8-bit colour in 16-bit fields" + sampled;
        } else if (m_colorDepth == ColorDepth::SixteenBit) {
            detail += ", 16-bit colour scaled to 8 bits" + sampled;
        }
        return detail;
    }

    [[noreturn]] void throwOutOfBounds(const SourceNormalizer& normalizer, std::uint64_t index,
                                       const glm::dvec3& source) const {
        const InputLocation where = m_records->recordLocation(index);
        try {
            normalizer.throwOutOfBounds(m_info.path, where, source);
        } catch (const InputError& error) {
            throw InputError(error.kind(), m_info.path, where,
                             m_records->recordName(index) + ": " + error.detail());
        }
    }

    las::Header m_header;
    std::unique_ptr<LasRecordSource> m_records;
    std::uint64_t m_fileBytes;
    ColorDepth m_colorDepth = ColorDepth::None;
    std::uint64_t m_colorSamples = 0;
    std::size_t m_colorOffset = 0;
};

ReadSummary LasReader::read(const BatchConsumer& consumer, const ReadOptions& options) {
    ReadSummary summary;
    const auto cancelled = [&] {
        return options.cancel != nullptr && options.cancel->load();
    };
    if (cancelled()) {
        summary.cancelled = true;
        return summary;
    }
    const std::size_t batchPoints = std::max<std::size_t>(1, options.batchPoints);
    PointBatch batch;
    batch.attributes = m_info.attributes;

    // Half a quantisation step: header bounds written from rounded coordinates may miss a
    // point by that much. Points within it are clamped so batches stay inside the cube.
    const glm::dvec3 steps = glm::abs(m_header.scale);
    const double tolerance = 0.5 * std::max({steps.x, steps.y, steps.z});
    const SourceNormalizer normalizer(m_info.cube, m_info.sourceBounds, tolerance);
    const Bounds& bounds = m_info.sourceBounds;
    const bool hasColor = m_colorDepth != ColorDepth::None;
    const std::size_t stride = m_header.recordLength;
    const LasColumnLayout lasLayout = LasColumnLayout::of(m_info.attributes);
    // Every column is sized for a whole batch once and each run of points is written in
    // place: appending point by point cost a library call or a capacity check each, and
    // clearing the batch after each delivery had every column zero-filled again before it was
    // overwritten. `filled` counts the batch's points; only the last batch is cut to it.
    const std::size_t lasBytes = lasLayout.bytes;
    const std::size_t batchCapacity =
        static_cast<std::size_t>(std::min<std::uint64_t>(batchPoints, m_header.pointCount));
    const auto sizeColumns = [&](std::size_t points) {
        batch.positions.resize(points);
        batch.intensities.resize(points);
        if (hasColor) {
            batch.colors.resize(points);
        }
        batch.las.resize(points * lasBytes);
    };
    sizeColumns(batchCapacity);
    std::size_t filled = 0;
    const auto deliver = [&] {
        if (batch.positions.size() != filled) {
            sizeColumns(filled); // the last batch
        }
        consumer(batch);
        ++summary.batches;
        summary.pointsDelivered += filled;
        filled = 0;
    };
    // Loop invariants as locals: members read through `this` were reloaded after every store
    // into the batch (the compiler cannot rule out that the stores alias them).
    const glm::dvec3 scale = m_header.scale;
    const glm::dvec3 offset = m_header.offset;
    const glm::dvec3 low = bounds.min;
    const glm::dvec3 high = bounds.max;
    const bool sixteenBitColor = m_colorDepth == ColorDepth::SixteenBit;
    const std::size_t colorOffset = m_colorOffset;
    const std::uint8_t pointFormat = m_header.pointFormat;
    m_records->forEachBlock([&](const LasRecordBlock& block) {
        // The block a batch's worth of records at a time: positions, intensities and colours
        // point by point, then the LAS columns of the run in one call.
        for (std::uint64_t i = 0; i < block.count;) {
            const std::size_t at = filled;
            const auto take = static_cast<std::size_t>(
                std::min<std::uint64_t>(block.count - i, batchPoints - at));
            if (batch.positions.size() < at + take) {
                sizeColumns(at + take); // more records than the header declared
            }
            const std::uint8_t* records = block.records + i * stride;
            // A run is parsed in slices on the worker threads: the sorter's thread, which
            // consumes the batches, waits for the parse about half of the read phase, and a
            // slice keeps its core busy meanwhile. The bounds test is folded into one flag per
            // slice, so the loop has no branch; the first point out of bounds is found again
            // for its error.
            std::atomic<bool> allInBounds{true};
            const auto parseSlice = [&](std::size_t first, std::size_t last) {
                glm::vec3* positions = batch.positions.data() + at;
                std::uint16_t* intensities = batch.intensities.data() + at;
                bool sliceInBounds = true;
                for (std::size_t j = first; j < last; ++j) {
                    const std::uint8_t* record = records + j * stride;
                    const glm::dvec3 source = sourcePosition(record, scale, offset);
                    sliceInBounds &= normalizer.inBounds(source);
                    positions[j] = normalizer.toUnit(glm::clamp(source, low, high));
                    intensities[j] = loadRaw<std::uint16_t>(record + las::kRecordIntensity);
                }
                if (!sliceInBounds) {
                    allInBounds.store(false, std::memory_order_relaxed);
                }
                if (hasColor) {
                    glm::u8vec3* colors = batch.colors.data() + at;
                    for (std::size_t j = first; j < last; ++j) {
                        colors[j] = color(records + j * stride + colorOffset, sixteenBitColor);
                    }
                }
                las::readLasColumns(records + first * stride, last - first, stride, pointFormat,
                                    lasLayout, batch.las.data() + (at + first) * lasBytes);
            };
            if (take >= 2 * kParseSlicePoints) {
                tbb::parallel_for(tbb::blocked_range<std::size_t>(0, take, kParseSlicePoints),
                                  [&](const tbb::blocked_range<std::size_t>& slice) {
                                      parseSlice(slice.begin(), slice.end());
                                  });
            } else {
                parseSlice(0, take);
            }
            if (!allInBounds.load(std::memory_order_relaxed)) {
                for (std::size_t j = 0; j < take; ++j) {
                    const glm::dvec3 source = sourcePosition(records + j * stride, scale, offset);
                    if (!normalizer.inBounds(source)) {
                        throwOutOfBounds(normalizer, block.firstIndex + i + j, source);
                    }
                }
            }
            filled += take;
            i += take;
            if (filled == batchPoints) {
                deliver();
                const bool morePoints = block.firstIndex + i < m_header.pointCount;
                if (morePoints && cancelled()) {
                    summary.cancelled = true;
                    return false;
                }
            }
        }
        return true;
    });
    if (filled > 0) {
        deliver();
    }
    return summary;
}

} // namespace

std::unique_ptr<PointReader> openLasReader(const std::string& path, const OpenOptions& options) {
    auto stream = std::make_unique<FileStream>(path);
    const las::Header header = las::readHeader(*stream);
    if (header.compressed) {
        auto records = openLazRecords(std::move(stream), header);
        return std::make_unique<LasReader>(path, header, std::move(records), CloudFormat::Laz,
                                           options);
    }
    auto records = std::make_unique<LasFileRecords>(std::move(stream), header);
    return std::make_unique<LasReader>(path, header, std::move(records), CloudFormat::Las, options);
}

} // namespace omicron
