#include "sort/budgeted_cloud.hpp"

#include "io/atomic_file_writer.hpp"
#include "sort/scratch_folder.hpp"

#include <stdexcept>

namespace omicron {

std::shared_ptr<SortedCloud> makeSortedCloud(const CubeTransform& cube,
                                             const glm::dvec3& sourceOffset,
                                             AttributeSet attributes, std::size_t capacity,
                                             PointStorage storage, std::uint64_t budgetBytes,
                                             const std::string& tempDir) {
    if (storage == PointStorage::Exact && budgetBytes > 0 &&
        capacity * pointBytes(attributes) > budgetBytes / 2) {
        const std::string folder = tempDir.empty() ? ScratchFolder::defaultParent() : tempDir;
        try {
            return std::make_shared<SortedCloud>(cube, sourceOffset, attributes, capacity,
                                                 FileBacking{folder}, budgetBytes);
        } catch (const std::runtime_error& error) {
            throw OutputError(error.what()); // what() names the folder and the bytes
        }
    }
    return std::make_shared<SortedCloud>(cube, sourceOffset, attributes, capacity,
                                         CloudOrder::Morton, storage);
}

} // namespace omicron
