// The sorted cloud a stage fills (the sorter, the .oms reader), sized by the memory budget:
// in memory, or, when its exact points would take more than half the budget, in an unnamed
// scratch file kept out of memory beyond the budget (SortedCloud's FileBacking constructor).
#pragma once

#include "points/sorted_cloud.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace omicron {

// `budgetBytes` 0: always in memory. `tempDir` empty: ScratchFolder::defaultParent(). Throws
// OutputError naming the folder when the scratch file cannot be made or reserved there.
std::shared_ptr<SortedCloud> makeSortedCloud(const CubeTransform& cube,
                                             const glm::dvec3& sourceOffset,
                                             AttributeSet attributes, std::size_t capacity,
                                             PointStorage storage, std::uint64_t budgetBytes,
                                             const std::string& tempDir);

} // namespace omicron
