// How one sorted batch is cut into subtrees for the threads: each subtree is a contiguous
// range of the sorted voxels below one node. A scan fills only a few of the 8 (or 64) nodes
// near the root (at 0.1 m the whole scan usually lies in the 8 depth-2 nodes around the map
// origin), so a fixed split depth balances badly; instead ranges are cut deeper where the
// voxels are dense, until each holds at most `grain` voxels or the depth limit is reached.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "octree/morton_order.h"

namespace ort {

struct SubtreeRange {
  size_t begin = 0, end = 0;  // voxels [begin, end) of the sorted batch
  unsigned depth = 0;         // depth of the node whose subtree holds them (0 = root)
};

// Disjoint subtrees covering all voxels, in Morton order. With grain >= voxels.size() the
// result is one range at the root.
std::vector<SubtreeRange> split_into_subtrees(std::span<const SortedVoxel> voxels, size_t grain,
                                              unsigned max_depth);

}  // namespace ort
