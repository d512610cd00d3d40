#include "tree_checks.h"

#include "support/tree_compare.h"

namespace ort::test {

::testing::AssertionResult same_tree(const octomap::OcTree& reference, const octomap::OcTree& batched) {
  const size_t counted = batched.calcNumNodes();
  if (batched.size() != counted)
    return ::testing::AssertionFailure() << "size() " << batched.size() << " but " << counted << " nodes";
  const std::string shape = compare_structure(reference, batched);
  if (!shape.empty()) return ::testing::AssertionFailure() << "structure: " << shape;
  const TreeDiff leaves = compare_leaves(reference, batched);
  if (!leaves.maps_equal())
    return ::testing::AssertionFailure() << "leaves: " << leaves.differing_voxels << " voxels, "
                                         << leaves.differing_logodds << " log-odds differ; " << leaves.first_difference;
  return ::testing::AssertionSuccess();
}

}  // namespace ort::test
