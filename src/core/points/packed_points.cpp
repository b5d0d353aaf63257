#include "points/packed_points.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <tbb/parallel_for.h>

namespace omicron {

namespace {

int bitsFor(std::uint32_t spread) {
    return spread == 0 ? 0 : 32 - std::countl_zero(spread);
}

// Appends `width`-bit values to a little-endian bit stream.
class BitWriter {
public:
    explicit BitWriter(std::byte* out) : m_out(out) {}
    void put(std::uint32_t value, int width) {
        m_pending |= std::uint64_t{value} << m_pendingBits;
        m_pendingBits += width;
        while (m_pendingBits >= 8) {
            *m_out++ = static_cast<std::byte>(m_pending & 0xff);
            m_pending >>= 8;
            m_pendingBits -= 8;
        }
    }
    void flush() {
        if (m_pendingBits > 0) {
            *m_out++ = static_cast<std::byte>(m_pending & 0xff);
        }
    }

private:
    std::byte* m_out;
    std::uint64_t m_pending = 0;
    int m_pendingBits = 0;
};

// Bytes past the last block of a page, so that PackedPointStore::field's 8-byte loads stay
// inside the allocation.
constexpr std::size_t kPagePadding = 8;

} // namespace

PackedPointStore::PackedPointStore(std::size_t capacity, bool hasColors)
    : m_capacity(capacity), m_hasColors(hasColors),
      m_blocks(std::make_unique<std::atomic<const std::byte*>[]>(
          (capacity + kBlockPoints - 1) / kBlockPoints)) {}

PackedPointStore::Header PackedPointStore::headerFor(std::span<const glm::vec3> positions,
                                                     std::span<const glm::u8vec3> colors) {
    Header header{};
    std::uint32_t low[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX};
    std::uint32_t high[3] = {0, 0, 0};
    for (const glm::vec3& p : positions) {
        for (int axis = 0; axis < 3; ++axis) {
            const std::uint32_t cell = morton::quantize(p[axis]);
            low[axis] = std::min(low[axis], cell);
            high[axis] = std::max(high[axis], cell);
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        header.base[axis] = low[axis];
        header.widths[axis] = static_cast<std::uint8_t>(bitsFor(high[axis] - low[axis]));
    }
    if (!colors.empty()) {
        std::uint8_t lowColor[3] = {255, 255, 255};
        std::uint8_t highColor[3] = {0, 0, 0};
        for (const glm::u8vec3& c : colors) {
            for (int channel = 0; channel < 3; ++channel) {
                lowColor[channel] = std::min(lowColor[channel], c[channel]);
                highColor[channel] = std::max(highColor[channel], c[channel]);
            }
        }
        for (int channel = 0; channel < 3; ++channel) {
            header.colorBase[channel] = lowColor[channel];
            header.widths[3 + channel] =
                static_cast<std::uint8_t>(bitsFor(highColor[channel] - lowColor[channel]));
        }
    }
    int record = 0;
    for (const std::uint8_t width : header.widths) {
        record += width;
    }
    header.recordBits = static_cast<std::uint8_t>(record);
    return header;
}

std::size_t PackedPointStore::blockBytes(const Header& header, std::size_t points) {
    return sizeof(Header) + (points * header.recordBits + 7) / 8;
}

void PackedPointStore::encode(const Header& header, std::span<const glm::vec3> positions,
                              std::span<const glm::u8vec3> colors, std::byte* out) {
    std::memcpy(out, &header, sizeof(Header));
    BitWriter writer(out + sizeof(Header));
    for (std::size_t i = 0; i < positions.size(); ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            writer.put(morton::quantize(positions[i][axis]) - header.base[axis],
                       header.widths[axis]);
        }
        if (!colors.empty()) {
            for (int channel = 0; channel < 3; ++channel) {
                writer.put(static_cast<std::uint32_t>(colors[i][channel] -
                                                      header.colorBase[channel]),
                           header.widths[3 + channel]);
            }
        }
    }
    writer.flush();
}

void PackedPointStore::append(std::span<const glm::vec3> positions,
                              std::span<const glm::u8vec3> colors) {
    assert(!m_hasColors || colors.size() == positions.size());
    assert(m_size + positions.size() <= m_capacity);
    if (positions.empty()) {
        return;
    }
    if (!m_hasColors) {
        colors = {};
    }
    // The short block the last append ended with is encoded again, whole or longer: its points
    // come first.
    const std::size_t first = m_size - m_tailPositions.size(); // first point of the first block
    const std::size_t points = m_tailPositions.size() + positions.size();
    const std::size_t blocks = (points + kBlockPoints - 1) / kBlockPoints;
    // The points of block b of this append: its first block joins the tail and the new points.
    std::vector<glm::vec3> headPositions;
    std::vector<glm::u8vec3> headColors;
    const std::size_t headFromNew =
        std::min(positions.size(), kBlockPoints - m_tailPositions.size());
    headPositions = m_tailPositions;
    headPositions.insert(headPositions.end(), positions.begin(),
                         positions.begin() + static_cast<std::ptrdiff_t>(headFromNew));
    if (!colors.empty()) {
        headColors = m_tailColors;
        headColors.insert(headColors.end(), colors.begin(),
                          colors.begin() + static_cast<std::ptrdiff_t>(headFromNew));
    }
    const auto blockPoints = [&](std::size_t b, std::span<const glm::vec3>& p,
                                 std::span<const glm::u8vec3>& c) {
        if (b == 0) {
            p = headPositions;
            c = headColors;
            return;
        }
        const std::size_t begin = headFromNew + (b - 1) * kBlockPoints;
        const std::size_t count = std::min(kBlockPoints, positions.size() - begin);
        p = positions.subspan(begin, count);
        c = colors.empty() ? colors : colors.subspan(begin, count);
    };

    // Sizes first, then one page for all blocks, then the bits (both passes in parallel).
    std::vector<Header> headers(blocks);
    std::vector<std::size_t> offsets(blocks + 1, 0);
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
        std::span<const glm::vec3> p;
        std::span<const glm::u8vec3> c;
        blockPoints(b, p, c);
        headers[b] = headerFor(p, c);
        offsets[b + 1] = blockBytes(headers[b], p.size());
    });
    for (std::size_t b = 0; b < blocks; ++b) {
        offsets[b + 1] += offsets[b];
    }
    auto page = std::make_unique<std::byte[]>(offsets[blocks] + kPagePadding);
    std::byte* base = page.get();
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
        std::span<const glm::vec3> p;
        std::span<const glm::u8vec3> c;
        blockPoints(b, p, c);
        encode(headers[b], p, c, base + offsets[b]);
    });
    for (std::size_t b = 0; b < blocks; ++b) {
        m_blocks[first / kBlockPoints + b].store(base + offsets[b], std::memory_order_release);
    }
    m_pages.push_back(std::move(page));
    m_pageBytes.fetch_add(offsets[blocks] + kPagePadding + sizeof(m_pages[0]),
                          std::memory_order_relaxed);
    m_size += positions.size();

    // Keep the points of a short last block for the next append.
    std::span<const glm::vec3> lastPositions;
    std::span<const glm::u8vec3> lastColors;
    if (m_size % kBlockPoints != 0) {
        blockPoints(blocks - 1, lastPositions, lastColors);
    }
    m_tailPositions.assign(lastPositions.begin(), lastPositions.end());
    m_tailColors.assign(lastColors.begin(), lastColors.end());
}

std::size_t PackedPointStore::bytesResident() const {
    return m_pageBytes.load(std::memory_order_relaxed) +
           (m_capacity + kBlockPoints - 1) / kBlockPoints * sizeof(m_blocks[0]);
}

} // namespace omicron
