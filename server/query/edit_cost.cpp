#include "query/edit_cost.h"

#include <algorithm>

namespace ort::query {
namespace {

using Node = octomap::OcTreeNode;

// Sub-cubes of side s of the cube [lo, lo + side) on one axis that overlap the box's range,
// and those inside it.
struct AxisCount {
  int64_t overlapping = 0, inside = 0;
};

AxisCount axis_count(int64_t lo, int64_t side, int64_t s, int64_t box_min, int64_t box_max) {
  const int64_t a = std::max(lo, box_min), b = std::min(lo + side - 1, box_max);
  AxisCount n;
  if (b < a) return n;
  n.overlapping = b / s - a / s + 1;
  const int64_t first = (a + s - 1) / s, last = (b + 1) / s - 1;  // cubes [k s, k s + s - 1] within [a, b]
  n.inside = std::max<int64_t>(0, last - first + 1);
  return n;
}

struct Walk {
  const octomap::OcTree& tree;
  const KeyBox& box;
  ClearTo to;
  Unknown unknown;
  const EditBounds& bounds;
  EditCost cost;

  bool over() {
    cost.over = cost.over || cost.work + cost.new_nodes > bounds.max_work || cost.new_nodes > bounds.max_new_nodes;
    return cost.over;
  }

  // The existing nodes of a subtree inside the box: a clear to unknown deletes each (a split
  // and a prune of 8 each), a clear to free marking unknown replaces the subtree by one leaf
  // the same way, a clear of known space sets each.
  void inside(const Node* node) {
    cost.work += to == ClearTo::kFree && unknown == Unknown::kKept ? 1 : 17;
    if (over() || !tree.nodeHasChildren(node)) return;
    for (unsigned i = 0; i < 8 && !cost.over; ++i)
      if (tree.nodeChildExists(node, i)) inside(tree.getNodeChild(node, i));
  }

  void below(const Node* node, const NodeCube& cube) {
    cost.work++;
    if (over()) return;
    if (cube_inside(cube, box)) return inside(node);
    if (!tree.nodeHasChildren(node)) {
      // A leaf across the border: split down to the finest cubes that straddle it (a clear
      // marking unknown space counts these with the whole box, from the root).
      if (!(to == ClearTo::kFree && unknown == Unknown::kMarked)) cost.new_nodes += 8 * straddling_cubes(cube, box);
      over();
      return;
    }
    for (unsigned i = 0; i < 8 && !cost.over; ++i) {
      if (!tree.nodeChildExists(node, i)) continue;
      const NodeCube c = child_cube(cube, i);
      if (overlap_voxels(c, box) > 0) below(tree.getNodeChild(node, i), c);
    }
  }
};

}  // namespace

int64_t straddling_cubes(const NodeCube& cube, const KeyBox& box) {
  int64_t total = 0;
  for (int64_t s = cube.side; s >= 2; s /= 2) {
    int64_t overlapping = 1, inside = 1;
    for (int a = 0; a < 3; ++a) {
      const AxisCount n = axis_count(cube.lo[a], cube.side, s, box.min[a], box.max[a]);
      overlapping *= n.overlapping;
      inside *= n.inside;
    }
    total += overlapping - inside;
  }
  return total;
}

EditCost estimate_clear_box(const octomap::OcTree& tree, const KeyBox& box, ClearTo to, Unknown unknown,
                            const EditBounds& bounds) {
  Walk w{tree, box, to, unknown, bounds, {}};
  NodeCube root;
  root.side = 1 << tree.getTreeDepth();
  if (to == ClearTo::kFree && unknown == Unknown::kMarked) {
    // Every straddling cube from the root down is made (or split) into 8, known or not.
    w.cost.new_nodes = 1 + 8 * straddling_cubes(root, box);
    if (w.over()) return w.cost;
  }
  if (tree.getRoot()) w.below(tree.getRoot(), root);
  return w.cost;
}

}  // namespace ort::query
