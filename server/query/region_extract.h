// Region extraction: the nodes of a key box at a chosen depth, as OctoMap's
// begin_leafs_bbx(min, max, depth) visits them (stored leaves, and the nodes at `depth`
// standing for their subtrees with OctoMap's inner value, the children's maximum), limited
// to those that share a voxel with the box. Occupied ones, and free ones when asked.
#pragma once

#include <cstddef>
#include <vector>

#include <octomap/OcTree.h>

#include "query/key_box.h"
#include "query/query_types.h"
#include "query/work_budget.h"

namespace ort::query {

struct RegionOptions {
  int depth = 0;  // 1 .. tree depth; 0 = finest
  bool include_free = false;
  size_t max_voxels = 1'000'000;  // more: QueryError (the reply would be too large)
};

// With a budget (one unit per node visited), a walk that runs out returns what it found so
// far with budget->cut set: not an answer.
std::vector<RegionVoxel> extract_region(const octomap::OcTree& tree, const KeyBox& box, const RegionOptions& opt,
                                        WorkBudget* budget = nullptr);

}  // namespace ort::query
