#include "sorted_cloud.hpp"

namespace omicron {

namespace {
template <typename T>
void copyInto(std::span<const T> from, std::size_t begin, std::size_t end, std::vector<T>& to) {
    if (!from.empty()) {
        to.assign(from.begin() + begin, from.begin() + end);
    } else {
        to.clear();
    }
}
} // namespace

void SortedCloud::copyRange(std::size_t begin, std::size_t end, PointBatch& out) const {
    assert(begin <= end && end <= sortedEnd());
    out.attributes = m_attributes;
    copyInto(positions(), begin, end, out.positions);
    copyInto(normals(), begin, end, out.normals);
    copyInto(colors(), begin, end, out.colors);
    copyInto(intensities(), begin, end, out.intensities);
}

} // namespace omicron
