// The one walk every box query, region extraction and the 2D grid share: the stored
// leaves (or nodes at max_depth) that share at least one finest voxel with a key box.
#pragma once

#include <octomap/OcTree.h>

#include "query/key_box.h"
#include "query/work_budget.h"

namespace ort::query {

// Calls f(node, cube, voxels shared with the box) for every node begin_leafs_bbx(box,
// max_depth) visits that shares a voxel with the box; f returns false to stop.
// max_depth 0 = the finest level. Why the shared count is recomputed here: OctoMap's bbx
// iterator's overlap test is one voxel generous on the min side (child.key + half >=
// min.key, where the child ends at key + half - 1), so it also yields nodes that end just
// below the box; they share nothing and are skipped.
// With a budget, every node visited costs one unit; the walk stops where it runs out
// (budget->cut says why) and the caller's partial result is not an answer.
template <class F>
void for_each_node_in(const octomap::OcTree& tree, const KeyBox& box, unsigned max_depth, F&& f,
                      WorkBudget* budget = nullptr) {
  const unsigned top = tree.getTreeDepth();
  for (auto it = tree.begin_leafs_bbx(box.min, box.max, static_cast<unsigned char>(max_depth)),
            end = tree.end_leafs_bbx();
       it != end; ++it) {
    if (budget && !budget->charge(1)) return;
    const NodeCube cube = node_cube(it.getKey(), it.getDepth(), top);
    const int64_t n = overlap_voxels(cube, box);
    if (n == 0) continue;
    if (!f(static_cast<const octomap::OcTreeNode&>(*it), cube, n)) return;
  }
}

}  // namespace ort::query
