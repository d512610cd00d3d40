// Box queries: how many finest-level voxels of a key box are occupied, free and unknown
// (a voxel's state is search(key)'s: no node = unknown), and whether any is occupied.
//
// Counted per stored leaf, not per voxel: begin_leafs_bbx visits the leaves touching the
// box (a pruned leaf stands for up to 2^(3(16-depth)) voxels), each adds the voxels it
// shares with the box, and unknown = box voxels - occupied - free. A 5 m box of unknown
// space at 0.05 m (10^6 voxels) costs a few node visits instead of 10^6 searches.
#pragma once

#include <octomap/OcTree.h>

#include "query/key_box.h"
#include "query/query_types.h"
#include "query/work_budget.h"

namespace ort::query {

// With a budget: one unit per node visited; when it runs out (budget->cut) the result is
// partial and must not be reported.
BoxCounts count_box(const octomap::OcTree& tree, const KeyBox& box, WorkBudget* budget = nullptr);
// Stops at the first occupied voxel (a footprint check).
bool any_occupied(const octomap::OcTree& tree, const KeyBox& box, WorkBudget* budget = nullptr);

}  // namespace ort::query
