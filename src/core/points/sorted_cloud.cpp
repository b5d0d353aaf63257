#include "points/sorted_cloud.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace omicron {

namespace {

// `values` as the first elements of `array`: a file-backed array is written as the staged ranges
// are (its mapping reads it back), the rest of its reserved space staying unused.
template <typename T> void storeFirst(HugePageArray<T>& array, std::span<const T> values) {
    assert(array.size() >= values.size());
    if (array.fileBacked()) {
        array.writeAt(0, values);
    } else {
        std::copy(values.begin(), values.end(), array.data());
    }
}

} // namespace

const char* toString(PointStorage storage) {
    return storage == PointStorage::Packed ? "packed" : "exact";
}

bool parsePointStorage(std::string_view text, PointStorage& out) {
    if (text == "exact") {
        out = PointStorage::Exact;
    } else if (text == "packed") {
        out = PointStorage::Packed;
    } else {
        return false;
    }
    return true;
}

SortedCloud::SortedCloud(const CubeTransform& cube, const glm::dvec3& sourceOffset,
                         AttributeSet attributes, std::size_t capacity, CloudOrder order,
                         PointStorage storage, PageSize pages)
    : m_cube(cube), m_sourceOffset(sourceOffset), m_attributes(attributes), m_order(order),
      m_capacity(capacity), m_pages(pages),
      m_positions(storage == PointStorage::Exact ? capacity : 0, pages),
      m_normals(attributes.has(Attribute::Normal) ? capacity : 0, pages),
      m_colors(storage == PointStorage::Exact && attributes.has(Attribute::Color) ? capacity : 0,
               pages),
      m_intensities(attributes.has(Attribute::Intensity) ? capacity : 0, pages),
      m_las(capacity * attributes.lasBytes(), pages),
      m_blockCodes(order == CloudOrder::Morton ? blockCodeCount(capacity) : 0) {
    if (pages == PageSize::Small &&
        (storage != PointStorage::Exact || order != CloudOrder::NodeOrder)) {
        throw std::invalid_argument("SortedCloud: only an exact node-order cloud is paged");
    }
    if (storage == PointStorage::Packed) {
        m_packed = std::make_unique<PackedPointStore>(capacity, attributes.has(Attribute::Color));
    }
}

SortedCloud::SortedCloud(const CubeTransform& cube, const glm::dvec3& sourceOffset,
                         AttributeSet attributes, std::size_t capacity, const FileBacking& backing,
                         std::uint64_t budgetBytes)
    : m_cube(cube), m_sourceOffset(sourceOffset), m_attributes(attributes),
      m_order(CloudOrder::Morton), m_capacity(capacity), m_pages(PageSize::Huge),
      m_positions(capacity, backing),
      m_normals(attributes.has(Attribute::Normal) ? capacity : 0, backing),
      m_colors(attributes.has(Attribute::Color) ? capacity : 0, backing),
      m_intensities(attributes.has(Attribute::Intensity) ? capacity : 0, backing),
      m_las(capacity * attributes.lasBytes(), backing), m_blockCodes(blockCodeCount(capacity)) {
    m_governor = std::make_unique<ResidentSetGovernor>(budgetBytes, [this] {
        m_positions.dropResident();
        m_normals.dropResident();
        m_colors.dropResident();
        m_intensities.dropResident();
        m_las.dropResident();
    });
}

SortedCloud::~SortedCloud() = default;

SortedCloud::InPlaceArrays SortedCloud::inPlaceArrays() {
    if (fileBacked()) {
        return {};
    }
    const auto bytes = [](auto& array) {
        return array.size() == 0
                   ? std::span<std::byte>()
                   : std::span(reinterpret_cast<std::byte*>(array.data()), array.bytesAllocated());
    };
    // The packed store has no position and colour arrays: it stages and encodes them.
    return {bytes(m_positions), bytes(m_normals), bytes(m_colors), bytes(m_intensities),
            bytes(m_las)};
}

void SortedCloud::setUniformColumns(const std::uint16_t* intensity, const std::uint8_t* lasRecord) {
    assert(m_sortedEnd.load(std::memory_order_relaxed) == 0);
    if (intensity != nullptr) {
        storeFirst(m_intensities, std::span(intensity, 1));
        m_intensityStride = 0;
    }
    if (lasRecord != nullptr) {
        storeFirst(m_las, std::span(lasRecord, m_attributes.lasBytes()));
        m_lasStride = 0;
    }
}

SortedCloud::StagedRange SortedCloud::stage(std::size_t end) {
    const std::size_t begin = m_sortedEnd.load(std::memory_order_relaxed);
    assert(begin <= end && end <= m_capacity);
    const std::size_t count = end - begin;
    const auto inPlace = [&](auto& array) {
        return array.size() == 0 ? std::span<std::remove_reference_t<decltype(array[0])>>()
                                 : std::span(array.data() + begin, count);
    };
    const std::size_t lasBytes = m_attributes.lasBytes();
    // A uniform column is not staged: its one value is stored already.
    StagedRange staged{inPlace(m_positions), inPlace(m_normals), inPlace(m_colors),
                       m_intensityStride == 0 ? std::span<std::uint16_t>() : inPlace(m_intensities),
                       lasBytes == 0 || m_lasStride == 0
                           ? std::span<std::uint8_t>()
                           : std::span(m_las.data() + begin * lasBytes, count * lasBytes)};
    if (m_packed) {
        m_stagedPositions.resize(count);
        staged.positions = m_stagedPositions;
        if (m_packed->hasColors()) {
            m_stagedColors.resize(count);
            staged.colors = m_stagedColors;
        }
    }
    if (fileBacked()) { // written to the scratch files by publish(), not through the mapping
        const auto buffer = [&](auto& array, auto& vector, auto& span) {
            if (array.size() != 0) {
                vector.resize(span.size());
                span = vector;
            }
        };
        buffer(m_positions, m_stagedPositions, staged.positions);
        buffer(m_normals, m_stagedNormals, staged.normals);
        buffer(m_colors, m_stagedColors, staged.colors);
        buffer(m_intensities, m_stagedIntensities, staged.intensities);
        buffer(m_las, m_stagedLas, staged.las);
    }
    return staged;
}

void SortedCloud::writeStaged(std::size_t begin) {
    const std::size_t lasBytes = m_attributes.lasBytes();
    m_positions.writeAt(begin, std::span<const glm::vec3>(m_stagedPositions));
    m_normals.writeAt(begin, std::span<const glm::vec3>(m_stagedNormals));
    m_colors.writeAt(begin, std::span<const glm::u8vec3>(m_stagedColors));
    m_intensities.writeAt(begin, std::span<const std::uint16_t>(m_stagedIntensities));
    m_las.writeAt(begin * lasBytes, std::span<const std::uint8_t>(m_stagedLas));
    m_stagedPositions.clear();
    m_stagedNormals.clear();
    m_stagedColors.clear();
    m_stagedIntensities.clear();
    m_stagedLas.clear();
}

void SortedCloud::publish(std::size_t newSortedEnd) {
    const std::size_t previous = m_sortedEnd.load(std::memory_order_relaxed);
    assert(newSortedEnd >= previous && newSortedEnd <= capacity());
    if (m_packed && newSortedEnd > previous) {
        // Encodes what stage() handed out (all of it: a packed cloud publishes whole stages).
        assert(m_stagedPositions.size() == newSortedEnd - previous);
        m_packed->append(m_stagedPositions, m_stagedColors);
        m_stagedPositions.clear();
        m_stagedColors.clear();
    }
    // A file-backed cloud's new range is still in the staging buffers stage() handed out (all
    // of it: it publishes whole stages): its block codes come from there, not through the
    // mapping, which would fault every page in; then it goes to the files.
    const bool staged = fileBacked() && newSortedEnd > previous;
    assert(!staged || m_stagedPositions.size() == newSortedEnd - previous);
    if (m_blockCodes.size() != 0) {
        for (std::size_t block = blockCodeCount(previous); block < blockCodeCount(newSortedEnd);
             ++block) {
            const std::size_t i = block * kBlockCodePoints;
            const glm::vec3 p = staged ? m_stagedPositions[i - previous] : position(i);
            m_blockCodes[block] = morton::encodeUnit(p.x, p.y, p.z);
        }
    }
    if (staged) {
        writeStaged(previous);
    }
    assert(m_order != CloudOrder::Morton || previous == 0 || newSortedEnd == previous ||
           code(previous - 1) <= code(previous));
    m_sortedEnd.store(newSortedEnd, std::memory_order_release);
    // A merge or a stream fills a file-backed cloud faster than the governor's thread may
    // be scheduled on a busy machine: look after every published range too.
    keepWithinBudget();
}

void SortedCloud::markComplete() {
    // Staging buffers are only needed while a producer writes.
    m_stagedPositions = {};
    m_stagedNormals = {};
    m_stagedColors = {};
    m_stagedIntensities = {};
    m_stagedLas = {};
    m_complete.store(true, std::memory_order_release);
}

std::size_t SortedCloud::bytesResident() const {
    // A uniform column holds one value (on one page, counted as nothing).
    const std::size_t arrays =
        positions().size_bytes() + normals().size_bytes() + colors().size_bytes() +
        m_intensities.size() * m_intensityStride * sizeof(std::uint16_t) + m_capacity * m_lasStride;
    return (fileBacked() ? 0 : arrays) + m_blockCodes.size() * sizeof(morton::Code) +
           (m_packed ? m_packed->bytesResident() : 0);
}

void SortedCloud::willRead(std::size_t begin, std::size_t end) const {
    if (!fileBacked()) {
        return;
    }
    m_positions.willRead(begin, end);
    m_normals.willRead(begin, end);
    m_colors.willRead(begin, end);
    m_intensities.willRead(begin, end);
    const std::size_t lasBytes = m_attributes.lasBytes();
    m_las.willRead(begin * lasBytes, end * lasBytes);
}

std::uint64_t SortedCloud::residentDrops() const {
    return m_governor ? m_governor->drops() : 0;
}

void SortedCloud::copyRange(std::size_t begin, std::size_t end, PointBatch& out) const {
    assert(begin <= end && end <= sortedEnd());
    out.attributes = m_attributes;
    out.positions.resize(end - begin);
    for (std::size_t i = begin; i < end; ++i) {
        out.positions[i - begin] = position(i);
    }
    out.colors.clear();
    if (hasColors()) {
        out.colors.resize(end - begin);
        for (std::size_t i = begin; i < end; ++i) {
            out.colors[i - begin] = color(i);
        }
    }
    const auto copyInto = [&](auto from, auto& to) {
        if (!from.empty()) {
            to.assign(from.begin() + begin, from.begin() + end);
        } else {
            to.clear();
        }
    };
    copyInto(normals(), out.normals);
    const std::size_t lasBytes = m_attributes.lasBytes();
    if (m_intensityStride != 0 || m_intensities.size() == 0) {
        copyInto(std::span<const std::uint16_t>(m_intensities), out.intensities);
    } else { // uniform
        out.intensities.assign(end - begin, m_intensities.data()[0]);
    }
    if (m_lasStride != 0 || lasBytes == 0) {
        out.las.assign(m_las.data() + begin * lasBytes, m_las.data() + end * lasBytes);
    } else { // uniform
        out.las.resize((end - begin) * lasBytes);
        for (std::size_t i = 0; i < end - begin; ++i) {
            std::memcpy(out.las.data() + i * lasBytes, m_las.data(), lasBytes);
        }
    }
}

} // namespace omicron
