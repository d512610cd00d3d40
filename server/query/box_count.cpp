#include "query/box_count.h"

#include "query/leaf_walk.h"

namespace ort::query {

BoxCounts count_box(const octomap::OcTree& tree, const KeyBox& box, WorkBudget* budget) {
  BoxCounts c;
  for_each_node_in(
      tree, box, 0,
      [&](const octomap::OcTreeNode& node, const NodeCube&, int64_t n) {
        (tree.isNodeOccupied(node) ? c.occupied : c.free) += n;
        return true;
      },
      budget);
  c.unknown = box.voxels() - c.occupied - c.free;
  return c;
}

bool any_occupied(const octomap::OcTree& tree, const KeyBox& box, WorkBudget* budget) {
  bool found = false;
  for_each_node_in(
      tree, box, 0,
      [&](const octomap::OcTreeNode& node, const NodeCube&, int64_t) {
        found = tree.isNodeOccupied(node);
        return !found;
      },
      budget);
  return found;
}

}  // namespace ort::query
